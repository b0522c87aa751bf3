"""World.snapshot(), restore(), reset() and pickling (README.md, "Python": snapshots).

restore + k steps gives the state hash of the uninterrupted run, for every dynamics
backend; reset(seed) gives the world a fresh load with that seed gives; bad bytes and
another world's bytes raise ValueError and change nothing; Lua scripts are refused.
"""

import pickle
import unittest

import numpy as np

import swarmsim
from common import ROOT, world

SNAPSHOT_WORLD = str(ROOT / "tests" / "data" / "worlds" / "snapshot.yaml")
DEVICES_WORLD = str(ROOT / "tests" / "data" / "worlds" / "snapshot_devices.yaml")
BACKENDS = ["kinematic", "planar", "box2d", "ode"]


def load(physics="box2d", seed=None, robots=30, **kwargs):
    return swarmsim.World(SNAPSHOT_WORLD, seed=seed, set={"physics": physics, "robots": robots},
                          threads=2, **kwargs)


def spin(robots):
    """A module-level controller (picklable by reference): every robot turns on the spot."""
    n = robots.count
    return {"leftMotor": np.full(n, 3.0), "rightMotor": np.full(n, -1.0)}


class SnapshotTest(unittest.TestCase):
    def test_restore_plus_steps_equals_the_uninterrupted_run(self):
        # One snapshot per run: with planar, box2d and ode taking one rebuilds the engine
        # from the scene, which is part of the run it is taken in (README.md).
        for physics in BACKENDS:
            for at in (0, 7, 18):
                with self.subTest(physics=physics, at=at):
                    w = load(physics, seed=4)
                    w.step(at)
                    state = w.snapshot()
                    at_hash = w.state_hash()
                    hashes = {}
                    for later in (18, 30, 41):
                        if later > at:
                            w.step(later - w.steps)
                            hashes[later] = w.state_hash()
                    self.assertNotEqual(hashes[30], hashes[41])
                    history = w.metric_history("mean_nearest_neighbor_distance")
                    r = load(physics, seed=4)
                    r.restore(state)
                    self.assertEqual(r.steps, at)
                    self.assertEqual(r.state_hash(), at_hash)
                    for later, h in hashes.items():
                        r.step(later - r.steps)
                        self.assertEqual(r.state_hash(), h, f"{physics}: restored at {at}, compared at {later}")
                    # What Python kept of the metrics came back with the state.
                    np.testing.assert_array_equal(r.metric_history("mean_nearest_neighbor_distance")[1],
                                                  history[1])
                    self.assertEqual(r.metrics, w.metrics)
                    # The original itself goes back too.
                    w.restore(state)
                    w.step(41 - at)
                    self.assertEqual(w.state_hash(), hashes[41])

    def test_swarm_devices_come_back_with_their_readings(self):
        # Robots with a range-and-bearing board, an IR transceiver, a light sensor and a
        # light, an LED and a blob camera, a ground sensor and a paint nozzle, driven from
        # Python between steps; every reading an observation holds must come back.
        def drive(w):
            n, k = 12, w.steps
            i = np.arange(n)
            mode = (i + k // 6) % 3
            left = np.where(mode == 2, -2.0, 4.0)
            right = np.where(mode == 1, -2.0, 4.0)
            w.set_joint_targets("devicebot", {"leftMotor": left, "rightMotor": right})
            w.set_range_and_bearing_data("devicebot", np.stack([i, np.full(n, k % 256), (i * k) % 256], 1))
            w.send_ir_messages("devicebot", np.stack([i, np.full(n, k % 256)], 1), send=(i + k) % 2 == 0)

        def readings(w):
            out = {"poses": w.poses(), "light": w.light("devicebot"), "ground": w.ground("devicebot")}
            for name, d in (("rab", w.range_and_bearing("devicebot")), ("ir", w.ir_messages("devicebot")),
                            ("blobs", w.blob_cameras("devicebot"))):
                for key, a in d.items():
                    out[name + "." + key] = a
            return out

        def same(a, b, why):
            self.assertEqual(a.keys(), b.keys())
            for key in a:
                np.testing.assert_array_equal(a[key], b[key], err_msg=f"{why}: {key}")

        for physics in ("kinematic", "box2d"):
            with self.subTest(physics=physics):
                w = swarmsim.World(DEVICES_WORLD, set={"physics": physics}, threads=2)
                for _ in range(8):
                    drive(w)
                    w.step()
                state = w.snapshot()
                at = readings(w)
                later = {}
                for k in (1, 6, 15):
                    while w.steps < 8 + k:
                        drive(w)
                        w.step()
                    later[k] = (w.state_hash(), readings(w))
                # Not trivial: messages heard and blobs seen.
                self.assertGreater(later[15][1]["rab.offsets"][-1], 0)
                self.assertGreater(later[15][1]["ir.offsets"][-1], 0)
                self.assertGreater(later[15][1]["blobs.offsets"][-1], 0)
                r = swarmsim.World(DEVICES_WORLD, set={"physics": physics}, threads=1)
                r.restore(state)
                same(readings(r), at, "restored")
                for k, (h, expected) in later.items():
                    while r.steps < 8 + k:
                        drive(r)
                        r.step()
                    self.assertEqual(r.state_hash(), h, f"{physics}, k = {k}")
                    same(readings(r), expected, f"{physics}, k = {k}")

    def test_pickling_goes_through_the_snapshot(self):
        for physics in ("box2d", "ode"):
            with self.subTest(physics=physics):
                w = load(physics, seed=2)
                w.step(9)
                copy = pickle.loads(pickle.dumps(w))
                self.assertEqual(copy.steps, 9)
                self.assertEqual(copy.state_hash(), w.state_hash())
                w.step(12)
                copy.step(12)
                self.assertEqual(copy.state_hash(), w.state_hash())
                np.testing.assert_array_equal(copy.poses(), w.poses())
        # A controller given to the constructor travels by reference.
        w = load("planar", seed=3, controllers={"footbot": spin})
        w.step(4)
        copy = pickle.loads(pickle.dumps(w))
        w.step(5)
        copy.step(5)
        self.assertEqual(copy.state_hash(), w.state_hash())

    def test_reset_equals_a_fresh_load_with_that_seed(self):
        for physics in BACKENDS:
            with self.subTest(physics=physics):
                w = load(physics)
                w.step(6)
                for seed in (11, None, 5, 11):
                    w.reset(seed)
                    self.assertEqual(w.steps, 0)
                    self.assertEqual(w.metric_history("covered_area")[0].size, 0)
                    w.step(8)
                    fresh = load(physics, seed=seed)
                    fresh.step(8)
                    self.assertEqual(w.state_hash(), fresh.state_hash(), f"{physics}, seed {seed}")
                    np.testing.assert_array_equal(w.poses(), fresh.poses())
                # Another seed places the robots elsewhere.
                w.reset(11)
                a = w.poses()
                w.reset(12)
                self.assertFalse(np.array_equal(a, w.poses()))

    def test_bad_bytes_raise_value_error_and_change_nothing(self):
        w = load("box2d", seed=3)
        w.step(3)
        good = w.snapshot()
        w.step(2)
        before = w.state_hash()
        rng = np.random.default_rng(1)
        bad = [b"", b"not a snapshot", good[:10], good[: len(good) // 2], good[:-1], good + b"x"]
        for at in rng.integers(0, len(good), 40):
            mutated = bytearray(good)
            mutated[at] ^= 1 << int(rng.integers(0, 8))
            bad.append(bytes(mutated))
        for data in bad:
            with self.assertRaises(ValueError):
                w.restore(data)
        self.assertEqual(w.state_hash(), before)
        w.step(1)  # still usable
        with self.assertRaises(TypeError):
            w.restore("a string")

    def test_another_worlds_bytes_raise_value_error(self):
        state = load("box2d", robots=30).snapshot()
        with self.assertRaisesRegex(ValueError, "30 robots"):
            load("box2d", robots=31).restore(state)
        with self.assertRaisesRegex(ValueError, "settings or parameters"):
            load("planar", robots=30).restore(state)

    def test_lua_scripts_are_refused_by_name(self):
        w = swarmsim.World(world("diffusion.yaml"), set={"robots": 3}, threads=1)
        with self.assertRaisesRegex(RuntimeError, r"robot 'footbot#0' runs Lua script '.*diffusion\.lua'"):
            w.snapshot()
        with self.assertRaisesRegex(RuntimeError, "Lua script"):
            pickle.dumps(w)
        # reset() is a snapshot of the start restored: refused in its own name.
        with self.assertRaisesRegex(
                RuntimeError, r"^reset\(\): robot 'footbot#0' runs Lua script .*"
                              r"or make a new World from the file$"):
            w.reset()
        w.step(1)  # refusing changed nothing


if __name__ == "__main__":
    unittest.main()
