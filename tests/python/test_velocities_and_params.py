"""World.set_velocities (README.md, "Python": writing state) on every dynamics backend, and
set_param values in the state hash and in snapshots (issue 30's leftovers, parts 2 and 3)."""

import math
import os
import tempfile
import unittest

import numpy as np

import swarmsim
from common import ROOT

BACKENDS = ["kinematic", "planar", "box2d", "ode"]

# A free body with nothing to slow it down (no wheels, no friction): it keeps
# what it is given for a step on every backend.
PUCK = """model: puck
objects: {name: body, type: shape, shape: cylinder, radius: 0.05, height: 0.04, dynamic: true,
          mass: 0.5, friction: 0}
"""
WORLD = """simulation: {physics: $physics, time_step: 0.1, physics_substeps: 10, seed: 1}
parameters: {physics: box2d}
models:
  - {model: puck.yaml, position: [0, 0]}
  - {model: puck.yaml, position: [1, 0]}
  - {model: puck.yaml, position: [0, 1], heading_deg: 90}
"""
SNAPSHOT_WORLD = str(ROOT / "tests" / "data" / "worlds" / "snapshot.yaml")


class SetVelocitiesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        with open(os.path.join(cls.dir.name, "puck.yaml"), "w") as f:
            f.write(PUCK)
        cls.path = os.path.join(cls.dir.name, "world.yaml")
        with open(cls.path, "w") as f:
            f.write(WORLD)

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def load(self, physics, threads=1):
        return swarmsim.World(self.path, set={"physics": physics}, threads=threads)

    def test_each_backend_moves_the_robots_by_v_dt(self):
        v = np.array([[0.3, 0.0, 0.0], [0.0, -0.2, 0.0], [0.1, 0.1, 1.0]])  # vx, vy, wz
        for physics in BACKENDS:
            with self.subTest(physics=physics):
                w = self.load(physics)
                w.step(2)  # settled on the ground (ode)
                start = w.poses(columns=7)
                yaw0 = w.poses(columns=3)[:, 2]
                w.set_velocities("puck", v)
                # Read back at once, in velocities()' columns.
                got = w.velocities("puck")
                np.testing.assert_allclose(got[:, [0, 1, 5]], v, atol=1e-12)
                w.step(1)
                end = w.poses(columns=7)
                # Exact without an engine; Box2D keeps float32 positions, ODE integrates.
                tol = 1e-9 if physics in ("kinematic", "planar") else 1e-4
                np.testing.assert_allclose(end[:, :2] - start[:, :2], v[:, :2] * 0.1, atol=tol)
                turned = (w.poses(columns=3)[:, 2] - yaw0 + math.pi) % (2 * math.pi) - math.pi
                np.testing.assert_allclose(turned, v[:, 2] * 0.1, atol=tol)
                # And the height is kept (the bodies stay on the ground).
                np.testing.assert_allclose(end[:, 2], start[:, 2], atol=1e-3)

    def test_six_columns_set_the_3d_velocity_and_the_rest_is_kept_by_three(self):
        w = self.load("kinematic")
        six = np.array([[0.1, 0.2, 0.3, 0.0, 0.0, 0.5]] * 3)
        w.set_velocities("puck", six)
        np.testing.assert_allclose(w.velocities("puck"), six, atol=1e-12)
        w.set_velocities("puck", np.array([[1.0, 2.0, 3.0]] * 3))  # vx, vy, wz; vz, wx, wy kept
        np.testing.assert_allclose(w.velocities("puck"), [[1.0, 2.0, 0.3, 0.0, 0.0, 3.0]] * 3,
                                   atol=1e-12)
        start = w.poses(columns=7)
        w.step(1)
        np.testing.assert_allclose(w.poses(columns=7)[:, :3] - start[:, :3],
                                   [[0.1, 0.2, 0.03]] * 3, atol=1e-12)
        # Kinematic has no inertia: after that step they stand still again.
        np.testing.assert_array_equal(w.velocities("puck"), np.zeros((3, 6)))
        after = w.poses(columns=7)
        w.step(3)
        np.testing.assert_array_equal(w.poses(columns=7), after)

    def test_deterministic_and_hashed_at_any_thread_count(self):
        for physics in BACKENDS:
            with self.subTest(physics=physics):
                hashes = set()
                for threads in (1, 2):
                    w = self.load(physics, threads)
                    w.step(2)
                    w.set_velocities("puck", [[0.2, 0.1, 0.5], [0.0, 0.3, -1.0], [-0.1, 0, 0]])
                    w.step(4)
                    hashes.add(w.state_hash())
                self.assertEqual(len(hashes), 1, physics)
                # A run without the write hashes otherwise.
                plain = self.load(physics, 2)
                plain.step(6)
                self.assertNotIn(plain.state_hash(), hashes)
                # Written and read back before any step: the hash sees it at once.
                a, b = self.load(physics), self.load(physics)
                a.set_velocities("puck", np.zeros((3, 3)))
                b.set_velocities("puck", [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1e-3, 0.0]])
                self.assertNotEqual(a.state_hash(), b.state_hash())

    def test_wrong_input_raises_and_sets_nothing(self):
        w = self.load("box2d")
        w.step(1)
        before = w.state_hash()
        for bad in (np.zeros((3, 4)), np.zeros((2, 3)), np.zeros(3), [[0, 0, 0]] * 4):
            with self.assertRaises(ValueError):
                w.set_velocities("puck", bad)
        with self.assertRaisesRegex(ValueError, "puck#2"):
            w.set_velocities("puck", [[0, 0, 0], [0, 0, 0], [np.nan, 0, 0]])
        with self.assertRaises(ValueError):
            w.set_velocities("puck", [[0, 0, 0], [0, 0, 0], [np.inf, 0, 0]])
        with self.assertRaises(TypeError):
            w.set_velocities("puck", np.ones((3, 3), dtype=bool))
        self.assertEqual(w.state_hash(), before)
        w.close()
        with self.assertRaises(RuntimeError):
            w.set_velocities("puck", np.zeros((3, 3)))

    def test_calling_from_inside_a_controller_raises(self):
        holder = {}

        def controller(robots):
            try:
                holder["w"].set_velocities("puck", np.zeros((3, 3)))
            except RuntimeError as e:
                holder["error"] = str(e)
            return {}

        w = swarmsim.World(self.path, set={"physics": "kinematic"}, controllers={"puck": controller})
        holder["w"] = w
        w.step(1)
        self.assertIn("set_velocities() while the world is stepping", holder.get("error", ""))

    def test_snapshots_keep_velocities_set_before_the_step(self):
        # kinematic keeps them in the scene; box2d and ode in the engine built from it.
        for physics in ("kinematic", "box2d", "ode"):
            with self.subTest(physics=physics):
                w = self.load(physics)
                w.step(2)
                w.set_velocities("puck", [[0.2, 0.1, 0.5], [0.0, 0.3, -1.0], [-0.1, 0, 0]])
                state = w.snapshot()
                w.step(3)
                r = self.load(physics)
                r.restore(state)
                r.step(3)
                self.assertEqual(r.state_hash(), w.state_hash())
                np.testing.assert_array_equal(r.poses(), w.poses())


def snapshot_world(seed=4):
    return swarmsim.World(SNAPSHOT_WORLD, seed=seed, set={"physics": "kinematic", "robots": 6},
                          threads=2)


class ParamHashTest(unittest.TestCase):
    def test_a_value_nobody_used_yet_changes_the_hash(self):
        # No script reads wheel_speed here (the python_controller entry dropped them).
        a, b, c = snapshot_world(), snapshot_world(), snapshot_world()
        self.assertEqual(a.state_hash(), b.state_hash())
        b.set_param("footbot", "wheel_speed", 0.2)
        self.assertNotEqual(a.state_hash(), b.state_hash())
        c.set_param("footbot", "wheel_speed", np.array([0.1, 0.1, 0.1, 0.1, 0.1, 0.2]))
        self.assertNotEqual(c.state_hash(), b.state_hash())
        self.assertNotEqual(c.state_hash(), a.state_hash())
        for w in (a, b, c):
            w.step(5)
        self.assertNotEqual(a.state_hash(), b.state_hash())
        # The same value twice: the same hash; set back to the file's value: as never set.
        d = snapshot_world()
        d.set_param("footbot", "wheel_speed", 0.2)
        d.step(5)
        self.assertEqual(d.state_hash(), b.state_hash())
        e, f = snapshot_world(), snapshot_world()
        e.set_param("footbot", "wheel_speed", 0.3)
        e.set_param("footbot", "wheel_speed", 0.1)  # the value snapshot.yaml gives
        self.assertEqual(e.state_hash(), f.state_hash())

    def test_a_value_outside_the_models_range_is_refused_as_set_refuses_it(self):
        # The e-puck declares wheel_speed's range, its top speed: 5 m/s drove
        # it at 0.6 m/s, five times what the robot can.
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "w.yaml")
            with open(path, "w") as f:
                f.write("simulation: {physics: kinematic}\n"
                        f"models: [{{model: {ROOT}/worlds/models/epuck.yaml, count: 2, "
                        "distribute: {region: {min: [0, 0], max: [1, 1]}}}]\n")
            with self.assertRaisesRegex(ValueError, r"within \[-0.1288, 0.1288\] m/s"):
                swarmsim.World(path, set={"epuck.wheel_speed": 5.0})
            w = swarmsim.World(path)
            before = w.param("epuck", "wheel_speed").copy()
            h = w.state_hash()
            for bad in (5.0, np.array([0.1, 0.2]), -0.13):
                with self.assertRaisesRegex(ValueError, r"parameter 'wheel_speed' of model 'epuck' "
                                                        r"must be within \[-0.1288, 0.1288\] m/s"):
                    w.set_param("epuck", "wheel_speed", bad)
            np.testing.assert_array_equal(w.param("epuck", "wheel_speed"), before)
            self.assertEqual(w.state_hash(), h, "nothing set")
            w.set_param("epuck", "wheel_speed", np.array([0.1288, -0.1288]))  # the bounds themselves
            np.testing.assert_array_equal(w.param("epuck", "wheel_speed"), [0.1288, -0.1288])
            w.close()

    def test_snapshots_carry_the_values_set(self):
        w = snapshot_world()
        w.step(2)
        w.set_param("footbot", "wheel_speed", np.linspace(0.1, 0.2, 6))
        state = w.snapshot()
        h = w.state_hash()
        r = snapshot_world()
        r.restore(state)
        self.assertEqual(r.state_hash(), h)
        np.testing.assert_array_equal(r.param("footbot", "wheel_speed"), np.linspace(0.1, 0.2, 6))
        # A snapshot taken before the write puts the loaded values back.
        fresh = snapshot_world()
        before = fresh.snapshot()
        fresh.set_param("footbot", "wheel_speed", 0.3)
        fresh.restore(before)
        np.testing.assert_array_equal(fresh.param("footbot", "wheel_speed"), np.full(6, 0.1))
        self.assertEqual(fresh.state_hash(), snapshot_world().state_hash())
        # reset() is a fresh load: the values set are gone.
        w.reset()
        np.testing.assert_array_equal(w.param("footbot", "wheel_speed"), np.full(6, 0.1))


if __name__ == "__main__":
    unittest.main()
