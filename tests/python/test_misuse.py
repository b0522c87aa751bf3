"""Misuse of the Python binding raises a clear Python exception instead of crashing
the interpreter (issue 30, part 1). Each case runs in a child interpreter, where a
crash shows as a signal exit instead of killing the test run."""

import os
import subprocess
import textwrap
import unittest

from common import PYTHON, ROOT, world

PRELUDE = f"""
import sys, threading, numpy as np, swarmsim
WORLD = {world("diffusion.yaml")!r}
def expect(exception, fragment, call, *args, **kwargs):
    try:
        call(*args, **kwargs)
    except exception as e:
        assert fragment in str(e), f"{{fragment!r}} not in {{e!r}}"
        return e
    raise AssertionError(f"{{call}} raised nothing, expected {{exception.__name__}}")
"""


def child(code, timeout=120):
    """Runs `code` in a fresh interpreter; returns (exit status, output)."""
    p = subprocess.run([PYTHON, "-c", PRELUDE + textwrap.dedent(code)], cwd=ROOT,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       env=dict(os.environ), timeout=timeout)
    return p.returncode, p.stdout


class MisuseTest(unittest.TestCase):
    def run_child(self, code):
        status, out = child(textwrap.dedent(code) + "\nprint('CHILD-OK')\n")
        self.assertEqual(status, 0, f"the child exited with {status} (a negative status is a "
                                    f"signal: a crash):\n{out}")
        self.assertIn("CHILD-OK", out)
        return out

    def test_a_kept_robots_object_raises_after_its_step(self):
        self.run_child("""
            kept = []
            def keep(robots):
                kept.append(robots)
                kept.append(robots.poses)       # an array taken during the call
                return None
            w = swarmsim.World(WORLD, seed=1, set={"robots": 4}, controllers={"footbot": keep})
            w.step(2)
            robots, poses = kept[2], kept[3]
            e = expect(RuntimeError, "belongs to step 1, which is over", lambda: robots.poses)
            expect(RuntimeError, "which is over", lambda: robots.count)
            expect(RuntimeError, "which is over", lambda: len(robots))
            expect(RuntimeError, "which is over", robots.param, "wheel_speed")
            expect(RuntimeError, "which is over", lambda: robots.range_and_bearing)
            assert "expired" in repr(robots)
            assert poses.shape == (4, 3) and np.all(np.isfinite(poses)), "the copy stays valid"
            w.close()
            expect(RuntimeError, "which is over", lambda: robots.poses)
            del w
            import gc; gc.collect()
            expect(RuntimeError, "which is over", lambda: robots.joint_positions)
        """)

    def test_close_inside_a_controller_raises_and_the_world_stays_usable(self):
        self.run_child("""
            holder = {}
            def closer(robots):
                try:
                    holder["w"].close()
                except RuntimeError as e:
                    holder["error"] = str(e)
                return None
            w = swarmsim.World(WORLD, seed=1, set={"robots": 4}, controllers={"footbot": closer})
            holder["w"] = w
            w.step(3)
            assert "close() inside a controller" in holder["error"], holder
            assert w.steps == 3
            w.step()
            assert w.steps == 4 and len(w.state_hash()) == 16
        """)

    def test_step_inside_a_controller_raises_and_an_uncaught_one_stops_the_run_clearly(self):
        self.run_child("""
            holder = {"caught": 0}
            def stepper(robots):
                try:
                    holder["w"].step()
                except RuntimeError as e:
                    holder["caught"] += 1
                    holder["error"] = str(e)
                return None
            w = swarmsim.World(WORLD, seed=1, set={"robots": 4}, controllers={"footbot": stepper})
            holder["w"] = w
            w.step(2)
            assert holder["caught"] == 2 and "step() inside a controller" in holder["error"]
            assert w.steps == 2

            def uncaught(robots):
                holder["v"].step()
            v = swarmsim.World(WORLD, seed=1, set={"robots": 4}, controllers={"footbot": uncaught})
            holder["v"] = v
            expect(RuntimeError, "step() inside a controller", v.step)
            expect(RuntimeError, "cannot be stepped again", v.step)
            v.poses()   # reading what the world holds still works
        """)

    def test_writers_and_step_worlds_inside_a_controller_raise(self):
        self.run_child("""
            seen = []
            def writer(robots):
                for call in (lambda: holder["w"].set_poses("footbot", np.zeros((4, 3))),
                             lambda: holder["w"].set_joint_targets("footbot", {"leftMotor": 0.0}),
                             lambda: swarmsim.step_worlds([holder["w"]])):
                    try:
                        call()
                    except RuntimeError as e:
                        seen.append(str(e))
                holder["poses"] = holder["w"].poses()   # reads work inside
                return None
            holder = {}
            w = swarmsim.World(WORLD, seed=1, set={"robots": 4}, controllers={"footbot": writer})
            holder["w"] = w
            w.step()
            assert len(seen) == 3, seen
            assert "while the world is stepping" in seen[0] and "while the world is stepping" in seen[1]
            assert "inside a controller" in seen[2] and "worlds[0]" in seen[2]
            assert holder["poses"].shape == (4, 3)
        """)

    def test_snapshot_restore_and_reset_inside_a_controller_raise(self):
        self.run_child("""
            seen = []
            def meddler(robots):
                for call in (lambda: holder["w"].snapshot(),
                             lambda: holder["w"].restore(b"x"),
                             lambda: holder["w"].reset(seed=3)):
                    try:
                        call()
                    except RuntimeError as e:
                        seen.append(str(e))
                return None
            holder = {}
            w = swarmsim.World(WORLD, seed=1, set={"robots": 4}, controllers={"footbot": meddler},
                               keep_scripts=False)
            holder["w"] = w
            w.step(2)
            assert len(seen) == 6, seen
            for name, text in zip(("snapshot()", "restore()", "reset()"), seen):
                assert name + " inside a controller" in text, (name, text)
            assert w.steps == 2
        """)

    def test_two_python_threads_stepping_one_world_take_turns(self):
        self.run_child("""
            w = swarmsim.World(WORLD, seed=5, set={"robots": 30}, threads=2)
            errors = []
            def run():
                try:
                    for _ in range(20):
                        w.step()
                        w.poses()
                except BaseException as e:
                    errors.append(e)
            threads = [threading.Thread(target=run) for _ in range(3)]
            for t in threads: t.start()
            for t in threads: t.join()
            assert not errors, errors
            assert w.steps == 60, w.steps
            alone = swarmsim.World(WORLD, seed=5, set={"robots": 30}, threads=1)
            alone.step(60)
            assert w.state_hash() == alone.state_hash(), "the steps interleaved whole"
        """)

    def test_close_from_another_thread_waits_for_the_step(self):
        self.run_child("""
            import time
            started = threading.Event()
            def slow(robots):
                started.set()
                time.sleep(0.05)   # releases the GIL inside the step
                return None
            w = swarmsim.World(WORLD, seed=1, set={"robots": 4}, controllers={"footbot": slow})
            t = threading.Thread(target=lambda: w.step(5))
            t.start()
            started.wait()
            w.close()              # waits until the other thread's step ends
            t.join()
            expect(RuntimeError, "closed", w.step)
            expect(RuntimeError, "closed", w.poses)
            expect(RuntimeError, "closed", lambda: w.planar)  # it still said True
        """)

    def test_keyboard_interrupt_and_system_exit_propagate_and_the_world_goes_on(self):
        self.run_child("""
            for exc in (KeyboardInterrupt, SystemExit):
                state = {"n": 0}
                def ctl(robots):
                    state["n"] += 1
                    if state["n"] == 3:
                        raise exc("stop here")
                    return {"leftMotor": 1.0, "rightMotor": 1.0}
                w = swarmsim.World(WORLD, seed=1, set={"robots": 4}, controllers={"footbot": ctl})
                try:
                    w.step(10)
                except exc as e:
                    assert "stop here" in str(e)
                else:
                    raise AssertionError("no " + exc.__name__)
                assert w.steps == 3, w.steps       # the step it was raised in finished
                w.step(2)
                assert w.steps == 5
        """)

    def test_thread_counts_outside_the_range_are_refused(self):
        self.run_child("""
            for bad in (-1, 1000):
                e = expect(ValueError, "0 (every core", swarmsim.World, WORLD, threads=bad)
                assert "1 to 256" in str(e) and str(bad) in str(e)
            expect(ValueError, "1 to 256", swarmsim.step_worlds, [], threads=-1)
            swarmsim.World(WORLD, set={"robots": 2}, threads=256).step()
        """)

    def test_set_mistakes_name_set_not_the_programs_option(self):
        # The loader's messages name the override as the user gave it (not '--set').
        self.run_child('''
            e = expect(ValueError, "World(set=...) robtos=4: no parameter 'robtos'",
                       swarmsim.World, WORLD, set={"robtos": 4})
            assert "--set" not in str(e), e
            expect(ValueError, "World(set=...) robots=abc: parameter 'robots' is a finite number",
                   swarmsim.World, WORLD, set={"robots": "abc"})
        ''')

    def test_step_counts_and_seeds_are_whole_numbers(self):
        self.run_child("""
            w = swarmsim.World(WORLD, set={"robots": 2})
            for bad in (True, 1.0, "1", None):
                expect(TypeError, "step(n): n must be an integer", w.step, bad)
            assert w.steps == 0, "nothing stepped"
            expect(ValueError, "n must be >= 0", w.step, -1)
            expect(ValueError, "out of range", w.step, 2**70)
            for bad in (True, 2.0):
                expect(TypeError, "step_worlds(n): n must be an integer", swarmsim.step_worlds,
                       [w], n=bad)
            assert w.steps == 0, "nothing stepped"
            w.step(np.int64(2))
            assert w.steps == 2
            for bad in (-1, 2**64):
                e = expect(ValueError, "must be from 0 to 18446744073709551615", swarmsim.World,
                           WORLD, seed=bad)
                assert str(bad) in str(e)
                expect(ValueError, "reset(seed) must be from 0", w.reset, bad)
            for bad in (True, 1.5, "7"):
                expect(TypeError, "World(seed=...) must be None or an integer", swarmsim.World,
                       WORLD, seed=bad)
                expect(TypeError, "reset(seed) must be None or an integer", w.reset, bad)
            a = swarmsim.World(WORLD, seed=2**64 - 1, set={"robots": 2})
            b = swarmsim.World(WORLD, seed=np.uint64(2**64 - 1), set={"robots": 2})
            assert a.state_hash() == b.state_hash()
        """)

    def test_paths_as_python_gives_them_and_messages_with_bytes_that_are_not_utf8(self):
        self.run_child(r"""
            import os, pathlib, tempfile
            # pathlib.Path, bytes and str all name the world file.
            for path in (pathlib.Path(WORLD), os.fsencode(WORLD), WORLD):
                swarmsim.World(path, set={"robots": 2}).close()
            expect(TypeError, "World(path) must be a path (str, bytes or os.PathLike), not int",
                   swarmsim.World, 5)
            expect(TypeError, "World(package_path=...) must be a list of paths",
                   swarmsim.World, WORLD, package_path="models")
            folder = os.fsencode(tempfile.mkdtemp())
            with open(os.path.join(folder, b"bot.yaml"), "wb") as f:
                f.write(b"model: bot\nobjects: {type: dummy, script: bad.lua}\n")
            with open(os.path.join(folder, b"bad.lua"), "wb") as f:
                f.write(b"function sysCall_actuation() error('bad \xff byte') end\n")
            # A file name that is not UTF-8, as os.listdir gives it (surrogate escapes).
            with open(os.path.join(folder, b"w\xff.yaml"), "wb") as f:
                f.write(b"simulation: {physics: kinematic, time_step: 0.1}\n"
                        b"models:\n  - {model: bot.yaml, position: [0, 0]}\n")
            listed = [n for n in os.listdir(os.fsdecode(folder)) if n.startswith("w")]
            assert listed == ["w\udcff.yaml"], listed
            w = swarmsim.World(os.path.join(os.fsdecode(folder), listed[0]))
            # Messages quoting such bytes arrive whole, each bad byte as U+FFFD.
            expect(RuntimeError, "bad \ufffd byte", w.step)
            e = expect(ValueError, "nothing\ufffd", swarmsim.World,
                       os.path.join(folder, b"nothing\xff.yaml"))
        """)

    def test_a_model_without_range_and_bearing_boards_is_a_value_error(self):
        self.run_child("""
            w = swarmsim.World(WORLD, set={"robots": 2})   # foot-bots without the board
            expect(ValueError, "no range-and-bearing board", w.range_and_bearing, "footbot")
            w2 = swarmsim.World(WORLD, set={"robots": 2, "footbot.with_rab": True})
            w2.step()
            r = w2.range_and_bearing("footbot")
            assert r["offsets"].shape == (3,)
        """)

    def test_wrong_shapes_and_names_are_value_errors(self):
        self.run_child("""
            w = swarmsim.World(WORLD, set={"robots": 10})
            expect(ValueError, "expected (10,)", w.set_joint_targets, "footbot",
                   {"leftMotor": np.zeros(3)})
            expect(ValueError, "not one of its joints (leftMotor, rightMotor)",
                   w.set_joint_targets, "footbot", {"noMotor": np.zeros(10)})
            expect(ValueError, "no model 'nope'", w.set_joint_targets, "nope", {})
            expect(ValueError, "(N, 3) x, y, yaw", w.set_poses, "footbot", np.zeros((10, 4)))
            expect(ValueError, "out= has shape (11, 3), expected (10, 3)", w.poses,
                   out=np.empty((11, 3)))
            expect(ValueError, "out= must be a plain numpy.ndarray, not a MaskedArray", w.poses,
                   out=np.ma.zeros((10, 3)))
        """)

    def test_thread_counts_and_snapshots_are_checked_by_name(self):
        self.run_child("""
            # Were pybind11's "incompatible constructor arguments" dumps.
            expect(ValueError, "World(threads=...): threads is 0", swarmsim.World, WORLD,
                   threads=2**40)
            expect(TypeError, "World(threads=...): threads must be an integer", swarmsim.World,
                   WORLD, threads=1.0)
            expect(TypeError, "World(set=...) must be a dict of {name: value}, not list",
                   swarmsim.World, WORLD, set=[("robots", 4)])
            expect(TypeError, "World(set=...): the key 4 is not a name (a str)", swarmsim.World,
                   WORLD, set={4: 4})
            expect(TypeError, "World(controllers=...) must be a dict of {name: value}, not str",
                   swarmsim.World, WORLD, controllers="footbot")
            still = {"footbot": lambda robots: {}}  # a Python controller: snapshots allowed
            w = swarmsim.World(WORLD, set={"robots": 4}, controllers=still, keep_scripts=False)
            expect(ValueError, "step_worlds: threads is 0", swarmsim.step_worlds, [w], 1, 999)
            state = w.snapshot()
            w.step(3)
            w.restore(bytearray(state))  # any bytes-like buffer
            w.restore(memoryview(state))
            expect(TypeError, "restore(state): state must be the bytes snapshot() returned, "
                   "not str", w.restore, "abc")
            other = swarmsim.World(WORLD, set={"robots": 5}, controllers=still,
                                   keep_scripts=False)
            e = expect(ValueError, "the snapshot is of this world's file", other.restore, state)
            assert "it holds 4 robots" in str(e), e
        """)

    def test_unknown_metrics_are_key_errors_listing_the_known_ones(self):
        self.run_child("""
            w = swarmsim.World(WORLD, set={"robots": 5})
            # A metric the world declares is known before its first sample.
            steps, values = w.metric_history("mean_nearest_neighbor_distance")
            assert len(steps) == 0
            e = expect(KeyError, "no metric 'nope'", w.metric_history, "nope")
            assert "mean_nearest_neighbor_distance" in str(e), e
            w.step(10)
            steps, values = w.metric_history("mean_nearest_neighbor_distance")
            assert list(steps) == [10], steps
            # The robot-level names are listed as such, the swarm-level ones apart
            # (they were listed as known robot-level metrics).
            e = expect(KeyError, "no robot-level metric 'nope' (the robots have recorded none "
                       "so far; the world's swarm-level metrics, read with metrics and "
                       "metric_history: mean_nearest_neighbor_distance", w.robot_metric, "nope")
        """)

    def test_complex_bool_and_nan_actions_are_refused_naming_the_robot(self):
        self.run_child("""
            w = swarmsim.World(WORLD, set={"robots": 3})
            before = w.state_hash()
            expect(TypeError, "complex", w.set_joint_targets, "footbot",
                   {"leftMotor": np.ones(3, dtype=complex)})
            expect(TypeError, "boolean", w.set_joint_targets, "footbot",
                   {"leftMotor": np.ones(3, dtype=bool)})
            expect(TypeError, "boolean", w.set_joint_targets, "footbot", {"leftMotor": True})
            expect(TypeError, "not numbers", w.set_joint_targets, "footbot", {"leftMotor": "fast"})
            e = expect(ValueError, "for robot 'footbot#1' is not finite", w.set_joint_targets,
                       "footbot", {"rightMotor": np.array([0.0, np.nan, 0.0])})
            # Nothing was set by the refused calls, the good key included.
            expect(ValueError, "not finite", w.set_joint_targets, "footbot",
                   {"leftMotor": np.ones(3), "rightMotor": np.full(3, np.inf)})
            assert w.state_hash() == before
            np.testing.assert_array_equal(w.joint_velocities(), 0)

            def complex_controller(robots):
                return {"leftMotor": np.ones(robots.count, dtype=complex)}
            c = swarmsim.World(WORLD, set={"robots": 3}, controllers={"footbot": complex_controller})
            expect(RuntimeError, "complex", c.step)
        """)

    def test_step_worlds_refuses_duplicates_closed_worlds_and_other_objects(self):
        self.run_child("""
            a = swarmsim.World(WORLD, set={"robots": 3}, threads=1)
            b = swarmsim.World(WORLD, set={"robots": 3}, threads=1)
            expect(ValueError, "worlds[2] is worlds[0]", swarmsim.step_worlds, [a, b, a])
            expect(TypeError, "worlds[1] is a str", swarmsim.step_worlds, [a, "b"])
            b.close()
            expect(RuntimeError, "worlds[1]", swarmsim.step_worlds, [a, b])
            assert a.steps == 0, "nothing stepped when the list is refused"
        """)

    def test_objects_made_by_new_without_init_raise(self):
        # World.__new__(World).step() crashed the interpreter: its methods ran on
        # memory pybind11 allocated for them, never initialised.
        self.run_child("""
            w = swarmsim.World.__new__(swarmsim.World)
            made = "World object was made by World.__new__ without World.__init__"
            for call in (w.step, w.close, w.snapshot, w.state_hash, lambda: w.steps,
                         lambda: w.poses(), lambda: w.robots):
                expect(TypeError, made, call)
            expect(TypeError, "worlds[0]", swarmsim.step_worlds, [w])
            r = swarmsim.Robots.__new__(swarmsim.Robots)
            expect(TypeError, "Robots object was made by Robots.__new__", lambda: r.count)
            expect(TypeError, "Robots object was made by Robots.__new__", lambda: r.poses)
            class Mine(swarmsim.World):
                pass
            expect(TypeError, "Mine object was made by Mine.__new__", Mine.__new__(Mine).step)
            del w, r
            w = swarmsim.World(WORLD, set={"robots": 3}, threads=1)  # a made one still works
            w.step(2)
            assert w.steps == 2
        """)


class DocstringTest(unittest.TestCase):
    def test_every_class_method_and_property_says_what_it_does(self):
        import swarmsim
        self.assertIn("step_worlds", swarmsim.__doc__)
        for cls in (swarmsim.World, swarmsim.Robots):
            self.assertGreater(len(cls.__doc__ or ""), 100, cls)
            for name, member in vars(cls).items():
                if name.startswith("_"):
                    continue
                doc = member.__doc__ or ""
                # pybind11 puts the signature first: a description must follow it.
                lines = [l for l in doc.splitlines() if l.strip() and not l.startswith(name + "(")]
                self.assertTrue(lines, f"{cls.__name__}.{name} has no description")
        lines = [l for l in swarmsim.step_worlds.__doc__.splitlines()
                 if l.strip() and not l.startswith("step_worlds(")]
        self.assertTrue(any("ValueError" in l for l in lines))


if __name__ == "__main__":
    unittest.main()
