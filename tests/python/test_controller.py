"""Python controllers (swarm/python/controller.cc): one vectorised call per step drives a
whole model (README.md, "Python")."""

import pathlib
import tempfile
import unittest

import numpy as np

import swarmsim
from common import ROOT, world

NUMPY_WORLD = world("python", "diffusion_numpy.yaml")
FOOTBOT = str(ROOT / "worlds" / "models" / "footbot.yaml")


def golden_rows():
    rows = []
    with open(ROOT / "tests" / "data" / "golden_hashes_python.tsv") as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            w, seed, steps, threads, h = line.rstrip("\n").split("\t")
            rows.append((w, int(seed), int(steps), int(threads), h))
    return rows


def write_world(folder, controller_code, entry_extra="", name="w.yaml"):
    """A small diffusion world in `folder` whose footbots run `controller_code`'s control()."""
    pathlib.Path(folder, "ctl.py").write_text(controller_code)
    path = pathlib.Path(folder, name)
    path.write_text(f"""simulation: {{physics: box2d, time_step: 0.1, seed: 1, steps: 20}}
arena: {{size: 4, wall_thickness: 0.1, wall_height: 0.2}}
models:
  - model: {FOOTBOT}
    count: 8
    distribute: {{region: arena}}
{entry_extra}""")
    return str(path)


class ControllerTest(unittest.TestCase):
    def test_the_numpy_diffusion_moves_robots_exactly_as_the_lua_one(self):
        lua = swarmsim.World(world("diffusion.yaml"), seed=5, set={"robots": 150, "density": 3.0})
        py = swarmsim.World(NUMPY_WORLD, seed=5, set={"robots": 150, "density": 3.0})
        self.assertNotIn("\n  script:", py.describe())  # no model's Lua script
        lua.step(60)
        py.step(60)
        np.testing.assert_array_equal(py.poses(), lua.poses())
        self.assertTrue((np.isfinite(py.proximity()).any()), "robots met obstacles on the way")

    def test_same_seed_same_hash_whatever_the_thread_count_and_the_golden_table(self):
        for w, seed, steps, threads, expected in golden_rows():
            run = swarmsim.World(str(ROOT / w), seed=seed, threads=threads)
            run.step(steps)
            self.assertEqual(run.state_hash(), expected,
                             f"{w} --seed {seed} --steps {steps} --threads {threads}: the hash "
                             "moved; if intended, update tests/data/golden_hashes_python.tsv")
        listed = {row[0] for row in golden_rows()}
        for path in sorted((ROOT / "worlds" / "python").glob("*.yaml")):
            self.assertIn(f"worlds/python/{path.name}", listed,
                          f"{path.name} has no row in tests/data/golden_hashes_python.tsv")

    def test_a_controller_beside_the_lua_scripts_overrides_their_targets(self):
        calls = []

        def stop(robots):
            calls.append((robots.step, robots.count, tuple(robots.joint_names)))
            return {"leftMotor": np.zeros(robots.count), "rightMotor": 0.0}

        w = swarmsim.World(world("diffusion.yaml"), seed=2, set={"robots": 25},
                           controllers={"footbot": stop})
        start = w.poses()
        w.step(10)
        self.assertEqual(len(calls), 10, "one call per step for all robots")
        self.assertEqual(calls[0][1:], (25, ("leftMotor", "rightMotor")))
        np.testing.assert_allclose(w.poses()[:, :2], start[:, :2], atol=1e-3)
        np.testing.assert_allclose(w.joint_velocities(), 0, atol=1e-6)

    def test_a_controller_that_sets_nothing_leaves_the_scripts_in_charge(self):
        seen = {}

        def watch(robots):
            seen["poses"] = robots.poses.copy()
            seen["names"] = robots.names
            seen["wheel"] = robots.param("wheel_speed")
            return None

        a = swarmsim.World(world("diffusion.yaml"), seed=4, set={"robots": 30},
                           controllers={"footbot": watch})
        b = swarmsim.World(world("diffusion.yaml"), seed=4, set={"robots": 30})
        a.step(15)
        b.step(15)
        np.testing.assert_array_equal(a.poses(), b.poses())
        self.assertEqual(seen["names"][29], "footbot#29")
        np.testing.assert_array_equal(seen["wheel"], np.full(30, 0.05))

    def test_driving_straight_covers_speed_times_time(self):
        def straight(robots):
            w = 0.04 / robots.param("wheel_radius")
            return {"leftMotor": w, "rightMotor": w}

        w = swarmsim.World(world("diffusion.yaml"), seed=1, set={"robots": 4, "density": 0.05},
                           controllers={"footbot": straight})
        w.step(1)
        before = w.poses()
        w.step(10)
        moved = np.linalg.norm(w.poses()[:, :2] - before[:, :2], axis=1)
        np.testing.assert_allclose(moved, 0.04 * 1.0, rtol=0.05)

    def test_a_controller_that_raises_stops_the_run_with_its_traceback(self):
        def broken(robots):
            if robots.step >= 2:
                return {"leftMotor": 1 / 0}
            return {}

        w = swarmsim.World(world("diffusion.yaml"), set={"robots": 5},
                           controllers={"footbot": broken})
        with self.assertRaises(RuntimeError) as e:
            w.step(5)
        message = str(e.exception)
        self.assertIn("ZeroDivisionError", message)
        self.assertIn("in broken", message)
        self.assertIn("in step 3 of the run (its robots.step was 2: robots.step counts the steps "
                      "finished before the call)", message)
        self.assertEqual(w.steps, 2, "the steps before the error stand")
        with self.assertRaises(RuntimeError) as again:
            w.step()
        self.assertIn("cannot be stepped again", str(again.exception))

    def test_a_controller_taking_no_argument_is_named_with_pythons_message(self):
        # Python raises before the function's first line: no traceback of it.
        def no_robots():
            return {}

        w = swarmsim.World(world("diffusion.yaml"), set={"robots": 2},
                           controllers={"footbot": no_robots})
        with self.assertRaises(RuntimeError) as e:
            w.step()
        message = str(e.exception)
        self.assertIn("the Python controller of model 'footbot' raised an exception", message)
        self.assertIn("TypeError", message)
        self.assertIn("takes 0 positional arguments but 1 was given", message)

    def test_bad_returns_are_clear_errors(self):
        cases = [
            (lambda r: {"leftMotor": np.zeros(r.count + 1)}, "expected (5,): one value per robot"),
            (lambda r: {"wheel": np.zeros(r.count)}, "not one of its joints (leftMotor, rightMotor)"),
            (lambda r: [1, 2], "must return a dict"),
            (lambda r: {"leftMotor": np.full(r.count, np.nan)}, "is not finite"),
            (lambda r: {"leftMotor": "fast"}, "is not numbers"),
        ]
        for function, expected in cases:
            w = swarmsim.World(world("diffusion.yaml"), set={"robots": 5},
                               controllers={"footbot": function})
            with self.assertRaises(RuntimeError) as e:
                w.step()
            self.assertIn(expected, str(e.exception))

    def test_python_controller_key_errors_name_the_file_and_line(self):
        with tempfile.TemporaryDirectory() as d:
            good = "def control(robots):\n    return {}\n"
            path = write_world(d, good, "    python_controller: missing.py\n")
            with self.assertRaises(ValueError) as e:
                swarmsim.World(path)
            self.assertIn("w.yaml:7:24", str(e.exception))
            self.assertIn("no file", str(e.exception))
            path = write_world(d, good, "    python_controller: ctl.py:nope\n")
            with self.assertRaises(ValueError) as e:
                swarmsim.World(path)
            self.assertIn("has no function 'nope'", str(e.exception))
            path = write_world(d, "def control(robots:\n", "    python_controller: ctl.py\n")
            with self.assertRaises(ValueError) as e:
                swarmsim.World(path)
            self.assertIn("SyntaxError", str(e.exception))
            self.assertIn("ctl.py\", line 1", str(e.exception))
            self.assertNotIn("importlib", str(e.exception), "the file's lines, not the import's")
            # An error while the file runs: its line in the file, and the error.
            path = write_world(d, "x = 1\ny = undefined_name\n" + good,
                               "    python_controller: ctl.py\n")
            with self.assertRaises(ValueError) as e:
                swarmsim.World(path)
            self.assertIn("ctl.py\", line 2, in <module>", str(e.exception))
            self.assertIn("NameError: name 'undefined_name' is not defined", str(e.exception))
            self.assertNotIn("importlib", str(e.exception))
            path = write_world(d, good, "    python_controller: ctl.lua\n")
            with self.assertRaises(ValueError) as e:
                swarmsim.World(path)
            self.assertIn("is a Python file", str(e.exception))

    def test_two_entries_of_one_model_with_different_controllers_are_an_error(self):
        with tempfile.TemporaryDirectory() as d:
            path = write_world(d, "def control(robots):\n    return {}\n",
                               "    python_controller: ctl.py\n"
                               f"  - model: {FOOTBOT}\n    count: 2\n    distribute: {{region: arena}}\n")
            with self.assertRaises(ValueError) as e:
                swarmsim.World(path)
            self.assertIn("has another models entry with no python_controller", str(e.exception))

    def test_keep_scripts_runs_lua_beside_python(self):
        with tempfile.TemporaryDirectory() as d:
            code = "def control(robots):\n    return {}\n"
            keep = write_world(d, code, "    python_controller: {file: ctl.py, keep_scripts: true}\n",
                               "keep.yaml")
            drop = write_world(d, code, "    python_controller: ctl.py\n")
            kept, dropped = swarmsim.World(keep), swarmsim.World(drop)
            self.assertIn("\n  script: ", kept.describe())
            self.assertNotIn("\n  script: ", dropped.describe())
            kept.step(5)
            dropped.step(5)
            self.assertTrue(np.any(kept.joint_velocities() != 0), "the Lua script drives")
            np.testing.assert_array_equal(dropped.joint_velocities(), 0)

    def test_close_frees_a_controller_that_refers_to_its_world(self):
        # The World kept the controllers it was made with (for pickling and reset) after
        # close(): one referring to its World was a cycle through C++ that Python's
        # collector cannot see, never freed (330 KiB a World of 8 robots).
        import gc
        import weakref

        class Token:
            pass

        tokens = []
        for _ in range(3):
            held = {"token": Token()}
            tokens.append(weakref.ref(held["token"]))
            w = swarmsim.World(NUMPY_WORLD, set={"robots": 4},
                               controllers={"footbot": lambda r, held=held: (held["w"].steps, {})[1]})
            held["w"] = w
            w.step(2)
            w.close()
            del w, held
        gc.collect()
        self.assertEqual([t() for t in tokens], [None] * 3)


if __name__ == "__main__":
    unittest.main()
