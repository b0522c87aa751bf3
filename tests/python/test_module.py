"""swarmsim's Python module (swarm/python/module.cc): a world that does not load, misuse,
and `python -m swarmsim` (README.md, "Python"). World itself: test_world.py."""

import json
import os
import signal
import subprocess
import tempfile
import time
import unittest

import numpy as np

import swarmsim
from common import BINARY, PYTHON, run, world


class ErrorTest(unittest.TestCase):
    def test_a_world_that_does_not_load_raises_with_the_programs_message(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "bad.yaml")
            with open(path, "w") as f:
                f.write("simulation:\n  physics: box2d\n  tim_step: 0.1\n")
            with self.assertRaises(ValueError) as e:
                swarmsim.World(path)
            self.assertIn("bad.yaml:3:3", str(e.exception))
            self.assertIn("time_step", str(e.exception))  # the suggestion
        with self.assertRaises(ValueError) as e:
            swarmsim.World("/no/such/world.yaml")
        self.assertIn("/no/such/world.yaml", str(e.exception))
        with self.assertRaises(ValueError) as e:
            swarmsim.World(world("diffusion.yaml"), set={"robotz": 3})
        self.assertIn("robotz", str(e.exception))

    def test_misuse_raises_instead_of_crashing(self):
        w = swarmsim.World(world("diffusion.yaml"), set={"robots": 10})
        with self.assertRaises(ValueError):
            w.poses(out=np.empty((10, 3), dtype=np.float32))
        with self.assertRaises(ValueError):
            w.poses(out=np.empty((11, 3)))
        with self.assertRaises(ValueError):
            w.poses(out=np.empty((3, 10)).T)
        with self.assertRaises(ValueError):
            w.step(-1)
        with self.assertRaises(ValueError):
            w.poses("no_such_model")
        with self.assertRaises(ValueError):
            w.set_joint_targets("footbot", {"leftMotor": np.zeros(3)})
        with self.assertRaises(ValueError):
            w.set_joint_targets("footbot", {"noMotor": np.zeros(10)})
        with self.assertRaises(TypeError):
            swarmsim.World(world("diffusion.yaml"), controllers={"footbot": 3})
        w.close()
        with self.assertRaises(RuntimeError):
            w.step()
        with self.assertRaises(RuntimeError):
            w.poses()


def write_python_world(folder, controller_code, count, extra=""):
    """A world in `folder` of `count` foot-bots driven by `controller_code`'s control()."""
    with open(os.path.join(folder, "ctl.py"), "w") as f:
        f.write(controller_code)
    path = os.path.join(folder, "w.yaml")
    with open(path, "w") as f:
        f.write("simulation: {physics: box2d, time_step: 0.1, seed: 1}\n"
                "arena: {size: 4, wall_thickness: 0.1, wall_height: 0.2}\n"
                "models:\n"
                f"  - model: {world('models', 'footbot.yaml')}\n"
                f"    count: {count}\n"
                "    distribute: {region: arena}\n"
                "    python_controller: ctl.py:control\n" + extra)
    return path


class RunTest(unittest.TestCase):
    def test_run_is_the_programs_run_and_ends_the_world(self):
        w = swarmsim.World(world("diffusion.yaml"), set={"robots": 10})
        with tempfile.TemporaryDirectory() as d:  # out_dir: the state hash is computed
            figures = w.run(20, out_dir=d, quiet=True)
        self.assertEqual(figures["steps"], 20)
        self.assertRegex(figures["state_hash"], "^[0-9a-f]{16}$")
        self.assertGreater(figures["wall_seconds"], 0)
        self.assertEqual(w.steps, 20)
        # The metrics are the World's too, as after step().
        self.assertEqual(list(w.metric_history("mean_nearest_neighbor_distance")[0]), [10, 20])
        fresh = swarmsim.World(world("diffusion.yaml"), set={"robots": 10})
        fresh.step(20)
        self.assertEqual(figures["state_hash"], fresh.state_hash())
        fresh.close()
        for call in (w.step, w.run):
            with self.assertRaisesRegex(RuntimeError, "ran it to its end"):
                call()
        self.assertEqual(w.poses().shape, (10, 3))  # still readable
        w.close()
        with self.assertRaisesRegex(ValueError, "steps must be >= 0"):
            swarmsim.World(world("diffusion.yaml"), set={"robots": 2}).run(-1)
        with self.assertRaisesRegex(TypeError, "run\\(out_dir=...\\) must be a path"):
            swarmsim.World(world("diffusion.yaml"), set={"robots": 2}).run(1, out_dir=3)

    def test_a_controllers_keyboard_interrupt_ends_the_run_with_its_outputs(self):
        def control(robots):
            if robots.step == 3:
                raise KeyboardInterrupt
            return {}
        w = swarmsim.World(world("diffusion.yaml"), set={"robots": 4},
                           controllers={"footbot": control})
        with tempfile.TemporaryDirectory() as d:
            with self.assertRaises(KeyboardInterrupt):
                w.run(50, out_dir=d, quiet=True)
            with open(os.path.join(d, "summary.json")) as f:
                summary = json.load(f)
            self.assertEqual((summary["status"], summary["steps"]), ("error", 3))
            self.assertIn("raised KeyboardInterrupt", summary["error"])
        w.close()


    def test_one_run_at_a_time_writes_into_a_folder(self):
        # run(out_dir) holds the folder as `swarmsim run --out` does (they
        # mixed their metrics and snapshots): a command-line run into it
        # meanwhile is refused, and run(out_dir) into a command-line run's.
        seen = {}
        with tempfile.TemporaryDirectory() as d:
            def control(robots):
                if robots.step == 3:
                    seen["cli"] = run([BINARY, "run", world("diffusion.yaml"), "--set", "robots=2",
                                       "--steps", "2", "--quiet", "--out", d])
                return {}
            w = swarmsim.World(world("diffusion.yaml"), set={"robots": 4},
                               controllers={"footbot": control})
            w.run(6, out_dir=d, quiet=True)
            w.close()
            code, out = seen["cli"]
            self.assertEqual(code, 2, out)
            self.assertIn("error: --out: another run (process %d) is writing into" % os.getpid(),
                          out)
            with open(os.path.join(d, "summary.json")) as f:
                self.assertEqual(json.load(f)["steps"], 6, "the first run's, whole")
            self.assertFalse(os.path.exists(os.path.join(d, ".swarmsim-lock")))

            cli = subprocess.Popen([BINARY, "run", world("diffusion.yaml"), "--set", "robots=2",
                                    "--steps", "1000000000", "--quiet", "--out", d],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            try:
                lock = os.path.join(d, ".swarmsim-lock")
                deadline = time.monotonic() + 60
                while time.monotonic() < deadline:  # until it holds the folder
                    try:
                        with open(lock) as f:
                            if f.read().strip() == str(cli.pid):
                                break
                    except OSError:
                        pass  # not made yet
                    time.sleep(0.01)
                other = swarmsim.World(world("diffusion.yaml"), set={"robots": 2})
                with self.assertRaisesRegex(ValueError, r"run\(out_dir=...\): another run "
                                            r"\(process %d\) is writing into" % cli.pid):
                    other.run(2, out_dir=d, quiet=True)
                self.assertEqual(other.steps, 0)
                other.close()
            finally:
                cli.terminate()
                cli.wait()


class ProgramTest(unittest.TestCase):
    def test_the_program_refuses_a_python_world_and_says_how_to_run_it(self):
        code, out = run([BINARY, "run", world("python", "diffusion_numpy.yaml"), "--steps", "2"])
        self.assertEqual(code, 2, out)
        self.assertIn("diffusion_numpy.yaml:26:5", out)
        self.assertIn("python3 -m swarmsim run", out)

    def test_python_m_swarmsim_run(self):
        env = {"PYTHONPATH": os.pathsep.join(filter(None, [os.environ.get("PYTHONPATH")]))}
        code, out = run([PYTHON, "-m", "swarmsim", "run", world("python", "diffusion_numpy.yaml"),
                         "--steps", "10", "--set", "robots=20", "--hash"], env)
        self.assertEqual(code, 0, out)
        self.assertRegex(out, r"state-hash: [0-9a-f]{16}")
        code, out = run([PYTHON, "-m", "swarmsim", "run", "/no/such.yaml"], env)
        self.assertEqual(code, 2, out)
        self.assertIn("/no/such.yaml", out)

    def test_python_m_swarmsim_run_writes_the_programs_outputs(self):
        numpy_world = world("python", "diffusion_numpy.yaml")
        with tempfile.TemporaryDirectory() as d:
            out_dir = os.path.join(d, "out")
            code, out = run([PYTHON, "-m", "swarmsim", "run", numpy_world, "--steps", "30",
                             "--set", "robots=20", "--out", out_dir, "--quiet", "--hash"])
            self.assertEqual(code, 0, out)
            self.assertNotIn("robot-ticks/s", out)  # --quiet: no summary table
            hash_line = [l for l in out.splitlines() if l.startswith("state-hash: ")]
            self.assertEqual(len(hash_line), 1, out)
            # The same state as stepping the world from Python.
            w = swarmsim.World(numpy_world, set={"robots": 20})
            w.step(30)
            self.assertEqual(hash_line[0], "state-hash: " + w.state_hash())
            history = w.metric_history("mean_nearest_neighbor_distance")
            w.close()
            with open(os.path.join(out_dir, "summary.json")) as f:
                summary = json.load(f)
            self.assertEqual((summary["status"], summary["steps"]), ("ok", 30))
            self.assertEqual(summary["state_hash"], hash_line[0].split()[1])
            self.assertTrue(summary["command"].startswith("python3 -m swarmsim run "), summary)
            self.assertEqual(summary["overrides"], {"robots": "20"})
            with open(os.path.join(out_dir, "metrics.csv")) as f:
                rows = [l.split(",") for l in f.read().splitlines()[1:]]
            self.assertEqual([int(r[0]) for r in rows], list(history[0]))
            for r, value in zip(rows, history[1]):
                self.assertAlmostEqual(float(r[4]), value, places=8)
            # Without --quiet: the summary table, as `swarmsim run` prints it.
            code, out = run([PYTHON, "-m", "swarmsim", "run", numpy_world, "--steps", "3",
                             "--set", "robots=4"])
            self.assertEqual(code, 0, out)
            self.assertIn("robot-ticks/s", out)
            # --out naming a file: bad input.
            code, out = run([PYTHON, "-m", "swarmsim", "run", numpy_world, "--steps", "3",
                             "--out", os.path.join(out_dir, "summary.json")])
            self.assertEqual(code, 2, out)
            self.assertIn("error: run(out_dir=...): '" + os.path.join(out_dir, "summary.json") +
                          "' is not a folder", out)

    def test_a_world_that_does_not_load_gets_the_programs_error_summary(self):
        # The folder of an earlier run kept its "ok" summary.json and its
        # metrics.csv, taken for this run's; a new folder was not made.
        numpy_world = world("python", "diffusion_numpy.yaml")
        with tempfile.TemporaryDirectory() as d:
            out_dir = os.path.join(d, "out")
            code, out = run([PYTHON, "-m", "swarmsim", "run", numpy_world, "--steps", "3",
                             "--set", "robots=4", "--out", out_dir, "--quiet"])
            self.assertEqual(code, 0, out)
            self.assertTrue(os.path.exists(os.path.join(out_dir, "metrics.csv")))
            for args, said in (([os.path.join(d, "nothere.yaml")], "nothere.yaml' not found"),
                               ([numpy_world, "--set", "robots=-3"], "robots")):
                for folder in (out_dir, os.path.join(d, "new")):
                    code, out = run([PYTHON, "-m", "swarmsim", "run"] + args +
                                    ["--steps", "3", "--out", folder, "--quiet"])
                    self.assertEqual(code, 2, out)
                    self.assertIn(said, out)
                    with open(os.path.join(folder, "summary.json")) as f:
                        summary = json.load(f)
                    self.assertEqual(summary["status"], "error", summary)
                    self.assertIn(said, summary["error"])
                    self.assertEqual(summary["world"], args[0])
                    self.assertTrue(summary["command"].startswith("python3 -m swarmsim run "))
                    self.assertFalse(os.path.exists(os.path.join(folder, "metrics.csv")))

    def test_a_failing_controller_keeps_the_outputs_of_the_steps_that_finished(self):
        with tempfile.TemporaryDirectory() as d:
            path = write_python_world(
                d, "def control(robots):\n"
                   "    if robots.step == 12:\n"
                   "        raise ValueError('bad reading')\n"
                   "    return {'leftMotor': 0.05, 'rightMotor': 0.05}\n", 4,
                "metrics:\n  - {name: mean_nearest_neighbor_distance, every: 5}\n")
            out_dir = os.path.join(d, "out")
            code, out = run([PYTHON, "-m", "swarmsim", "run", path, "--steps", "40",
                             "--out", out_dir, "--quiet"])
            self.assertEqual(code, 1, out)
            self.assertIn("ValueError: bad reading", out)
            self.assertIn("outputs of the 12 steps that finished are in", out)
            with open(os.path.join(out_dir, "summary.json")) as f:
                summary = json.load(f)
            self.assertEqual((summary["status"], summary["steps"]), ("error", 12))
            with open(os.path.join(out_dir, "metrics.csv")) as f:
                steps = [int(l.split(",")[0]) for l in f.read().splitlines()[1:]]
            self.assertEqual(steps, [5, 10])

    def test_ctrl_c_ends_the_run_as_interrupted_with_its_outputs(self):
        with tempfile.TemporaryDirectory() as d:
            path = write_python_world(
                d, "import pathlib, time\n"
                   "def control(robots):\n"
                   "    if robots.step == 5:\n"
                   f"        pathlib.Path({d!r}, 'started').touch()\n"
                   "    time.sleep(0.02)\n"  # a slow controller: the run is long enough
                   "    return {}\n", 2)
            out_dir = os.path.join(d, "out")
            p = subprocess.Popen([PYTHON, "-m", "swarmsim", "run", path, "--steps", "100000",
                                  "--out", out_dir, "--quiet"], stdout=subprocess.PIPE,
                                 stderr=subprocess.STDOUT, text=True)
            started = os.path.join(d, "started")
            for _ in range(6000):  # the controller has run 5 steps (at most 60 s)
                if os.path.exists(started) or p.poll() is not None:
                    break
                time.sleep(0.01)
            p.send_signal(signal.SIGINT)
            out, _ = p.communicate(timeout=120)
            self.assertEqual(p.returncode, 130, out)
            self.assertIn("interrupted by SIGINT", out)
            with open(os.path.join(out_dir, "summary.json")) as f:
                summary = json.load(f)
            self.assertEqual(summary["status"], "interrupted")
            self.assertGreaterEqual(summary["steps"], 5)


if __name__ == "__main__":
    unittest.main()
