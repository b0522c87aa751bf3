"""Writing state from Python between steps (issue 30, part 4): poses, joint states,
model parameters. Writes are deterministic and show in the state hash."""

import math
import unittest

import numpy as np

import swarmsim
from common import world

DIFFUSION = world("diffusion.yaml")


def still(robots):
    return {"leftMotor": 0.0, "rightMotor": 0.0}


class SetPosesTest(unittest.TestCase):
    def test_planar_poses_are_where_the_robots_stand_and_stay(self):
        w = swarmsim.World(DIFFUSION, seed=1, set={"robots": 4}, controllers={"footbot": still},
                           keep_scripts=False)
        target = np.array([[0.5, 0.5, 0.3], [-0.5, 0.5, -2.0], [0.5, -0.5, math.pi / 2],
                           [-0.5, -0.5, 3.0]])
        w.set_poses("footbot", target)
        np.testing.assert_allclose(w.poses(), target, atol=1e-12)
        w.step(5)
        # Standing still where they were put: the physics engine took the new poses.
        np.testing.assert_allclose(w.poses(), target, atol=1e-4)

    def test_a_driving_robot_starts_from_its_new_pose(self):
        def straight(robots):
            return {"leftMotor": 1.0, "rightMotor": 1.0}

        w = swarmsim.World(DIFFUSION, seed=1, set={"robots": 1},
                           controllers={"footbot": straight}, keep_scripts=False)
        w.set_poses("footbot", [[0.2, -0.3, math.pi / 2]])
        w.step(10)
        x, y, yaw = w.poses()[0]
        self.assertAlmostEqual(x, 0.2, delta=2e-3)          # heading +y: x unchanged
        self.assertGreater(y - (-0.3), 0.02)                # moved along +y
        self.assertAlmostEqual(yaw, math.pi / 2, delta=1e-2)

    def test_seven_columns_set_position_and_orientation(self):
        w = swarmsim.World(DIFFUSION, seed=1, set={"robots": 2})
        before = w.poses(columns=7)
        q = np.array([math.cos(0.25), 0, 0, math.sin(0.25)])     # yaw 0.5 rad
        target = np.array([[0.1, 0.2, before[0, 2], *(2 * q)],   # normalised on the way in
                           [-0.1, -0.2, before[1, 2], *q]])
        w.set_poses("footbot", target)
        got = w.poses(columns=7)
        np.testing.assert_allclose(got[:, :3], target[:, :3], atol=1e-12)
        np.testing.assert_allclose(got[:, 3:], [q, q], atol=1e-12)
        np.testing.assert_allclose(w.poses()[:, 2], [0.5, 0.5], atol=1e-12)

    def test_writes_are_deterministic_and_hashed(self):
        def run(write):
            w = swarmsim.World(DIFFUSION, seed=9, set={"robots": 10}, threads=2)
            w.step(3)
            if write:
                p = w.poses()
                p[:, 0] += 0.01
                w.set_poses("footbot", p)
            w.step(5)
            return w.state_hash()
        self.assertEqual(run(True), run(True))
        self.assertNotEqual(run(True), run(False))

    def test_bad_poses_change_nothing(self):
        w = swarmsim.World(DIFFUSION, seed=1, set={"robots": 3})
        before = w.state_hash()
        bad = np.zeros((3, 3))
        bad[2, 1] = np.nan
        with self.assertRaises(ValueError) as e:
            w.set_poses("footbot", bad)
        self.assertIn("footbot#2", str(e.exception))
        with self.assertRaises(ValueError):
            w.set_poses("footbot", np.full((3, 3), 2e6))
        with self.assertRaises(ValueError):
            w.set_poses("footbot", np.zeros((3, 7)))       # a zero quaternion
        with self.assertRaises(ValueError):
            w.set_poses("footbot", np.zeros((2, 3)))
        with self.assertRaises(TypeError):
            w.set_poses("footbot", np.zeros((3, 3), dtype=complex))
        self.assertEqual(w.state_hash(), before)
        w.close()
        with self.assertRaises(RuntimeError):
            w.set_poses("footbot", np.zeros((3, 3)))


class JointStateTest(unittest.TestCase):
    def test_joint_positions_jump_and_are_hashed(self):
        w = swarmsim.World(DIFFUSION, seed=1, set={"robots": 3})
        before = w.state_hash()
        q = np.array([[0.1, 0.2], [0.3, 0.4], [0.5, 0.6]])
        w.set_joint_positions("footbot", q)
        np.testing.assert_allclose(w.joint_positions("footbot"), q)
        self.assertNotEqual(w.state_hash(), before)
        w.set_joint_velocities("footbot", np.full((3, 2), 0.7))
        np.testing.assert_allclose(w.joint_velocities("footbot"), 0.7)
        with self.assertRaises(ValueError) as e:
            w.set_joint_positions("footbot", np.zeros((3, 3)))
        self.assertIn("leftMotor, rightMotor", str(e.exception))

    def test_joints_the_physics_engine_simulates_are_refused(self):
        w = swarmsim.World(world("hexapod.yaml"), seed=1, set={"robots": 1})
        w.step()
        joints = len(w.joint_names("hexapod"))
        with self.assertRaises(ValueError) as e:
            w.set_joint_positions("hexapod", np.zeros((1, joints)))
        self.assertIn("simulated by the dynamics backend", str(e.exception))


class SetParamTest(unittest.TestCase):
    def test_a_parameter_set_before_the_first_step_drives_the_scripts(self):
        w = swarmsim.World(DIFFUSION, seed=2, set={"robots": 6, "density": 0.05})
        start = w.poses()
        speeds = np.array([0.0, 0.05, 0.0, 0.05, 0.0, 0.05])
        w.set_param("footbot", "wheel_speed", speeds)
        np.testing.assert_array_equal(w.param("footbot", "wheel_speed"), speeds)
        w.step(10)
        moved = np.linalg.norm(w.poses()[:, :2] - start[:, :2], axis=1)
        np.testing.assert_allclose(moved[speeds == 0], 0, atol=1e-6)
        self.assertTrue(np.all(moved[speeds > 0] > 0.02), moved)

    def test_controllers_read_the_new_values_and_errors_name_the_parameters(self):
        seen = []

        def watch(robots):
            seen.append(robots.param("wheel_speed").copy())

        w = swarmsim.World(DIFFUSION, seed=2, set={"robots": 3}, controllers={"footbot": watch})
        w.step()
        w.set_param("footbot", "wheel_speed", 0.07)
        w.step()
        np.testing.assert_array_equal(seen[0], 0.05)
        np.testing.assert_array_equal(seen[1], 0.07)
        with self.assertRaises(ValueError) as e:
            w.set_param("footbot", "wheel_sped", 1.0)
        self.assertIn("wheel_speed", str(e.exception))
        with self.assertRaises(ValueError):
            w.set_param("footbot", "wheel_speed", np.zeros(4))
        with self.assertRaises(ValueError):
            w.set_param("footbot", "wheel_speed", np.nan)


class KeepScriptsTest(unittest.TestCase):
    def test_keep_scripts_false_leaves_the_robots_to_python(self):
        calls = []

        def nothing(robots):
            calls.append(robots.step)
            return None

        kept = swarmsim.World(DIFFUSION, seed=4, set={"robots": 5},
                              controllers={"footbot": nothing})
        dropped = swarmsim.World(DIFFUSION, seed=4, set={"robots": 5},
                                 controllers={"footbot": nothing}, keep_scripts=False)
        start = dropped.poses()
        kept.step(10)
        dropped.step(10)
        self.assertEqual(len(calls), 20)
        # Without the Lua diffusion script and with no targets, nobody drives.
        np.testing.assert_allclose(dropped.poses(), start, atol=1e-9)
        self.assertGreater(np.abs(kept.poses() - start).max(), 0.01)


if __name__ == "__main__":
    unittest.main()
