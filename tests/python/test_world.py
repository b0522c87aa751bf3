"""swarmsim.World (swarm/python/world.cc): loading, stepping, the arrays it reads,
metrics and describe (README.md, "Python")."""

import math
import os
import re
import tempfile
import unittest

import numpy as np

import swarmsim
from common import BINARY, ROOT, run, world


def program_hash(path, seed, steps, threads=1, sets=()):
    args = [BINARY, "run", path, "--seed", str(seed), "--steps", str(steps), "--threads",
            str(threads), "--hash", "--quiet"]
    for s in sets:
        args += ["--set", s]
    code, out = run(args)
    assert code == 0, out
    return re.search(r"state-hash: ([0-9a-f]{16})", out).group(1)


class WorldTest(unittest.TestCase):
    def test_steps_the_same_world_as_the_program(self):
        w = swarmsim.World(world("diffusion.yaml"), seed=7, set={"robots": 30}, threads=2)
        w.step(25)
        self.assertEqual(w.steps, 25)
        self.assertAlmostEqual(w.time, 2.5)
        self.assertEqual(w.state_hash(), program_hash(world("diffusion.yaml"), 7, 25, 1,
                                                      ["robots=30"]))
        w.close()
        # Closed: every accessor says so, the metrics and warnings too (they returned values).
        for read in (lambda: w.metrics, lambda: w.warnings, lambda: w.metric_names,
                     lambda: w.poses()):
            with self.assertRaisesRegex(RuntimeError, "closed"):
                read()

    def test_an_ode_world_steps_as_in_the_program(self):
        # ODE's solver threads and its constraint shuffle (the program's own
        # dRandInt) work the same inside the Python module as in the program.
        w = swarmsim.World(world("hexapod.yaml"), seed=3, set={"robots": 12}, threads=2)
        w.step(30)
        self.assertEqual(w.state_hash(), program_hash(world("hexapod.yaml"), 3, 30, 1,
                                                      ["robots=12"]))
        w.close()

    def test_poses_of_a_planar_world_move_as_the_robots_drive(self):
        w = swarmsim.World(world("diffusion.yaml"), seed=1, set={"robots": 40})
        self.assertTrue(w.planar)
        before = w.poses()
        self.assertEqual(before.shape, (40, 3))
        self.assertEqual(before.dtype, np.float64)
        w.step(20)
        after = w.poses()
        half = math.sqrt(40) / 2
        self.assertTrue(np.all(np.abs(after[:, :2]) < half), "robots left the walled arena")
        moved = np.linalg.norm(after[:, :2] - before[:, :2], axis=1)
        # Wheels at 0.05 m/s for 2 s: nobody goes farther than 0.1 m, most go some way.
        self.assertTrue(np.all(moved <= 0.1 * 1.01), moved.max())
        self.assertGreater(np.median(moved), 0.03)
        self.assertTrue(np.all(np.abs(after[:, 2]) <= math.pi))
        # out= reuses the caller's array.
        buf = np.empty((40, 3))
        self.assertIs(w.poses(out=buf), buf)
        np.testing.assert_array_equal(buf, after)
        names = w.robots["names"]
        self.assertEqual(len(names), 40)
        self.assertEqual(names[0], "footbot#0")

    def test_the_planar_backend_gives_planar_poses_too(self):
        # Decided by what the backend declares (planar), not by its name:
        # the planar contact backend was taken for 3D when only box2d was.
        w = swarmsim.World(world("diffusion_planar.yaml"), seed=1, set={"robots": 20})
        self.assertTrue(w.planar)
        w.step(10)
        p = w.poses()
        self.assertEqual(p.shape, (20, 3))
        self.assertTrue(np.all(np.abs(p[:, 2]) <= math.pi))
        w.close()

    def test_3d_poses_are_positions_and_unit_quaternions(self):
        w = swarmsim.World(world("wheeled3d.yaml"), seed=1)
        w.step(5)
        self.assertFalse(w.planar)
        p = w.poses()
        self.assertEqual(p.shape[1], 7)
        np.testing.assert_allclose(np.linalg.norm(p[:, 3:], axis=1), 1, atol=1e-9)
        self.assertTrue(np.all(p[:, 2] > -0.5), "robots fell through the floor")
        # The planar form's heading is the quaternion's yaw.
        flat = w.poses(columns=3)
        np.testing.assert_array_equal(flat[:, :2], p[:, :2])
        qw, qx, qy, qz = p[:, 3], p[:, 4], p[:, 5], p[:, 6]
        yaw = np.arctan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
        np.testing.assert_allclose(flat[:, 2], yaw, rtol=1e-15, atol=1e-15)
        with self.assertRaises(ValueError):
            w.poses(columns=4)

    def test_proximity_values_read_the_response_curve(self):
        # e-pucks (worlds/models/epuck.yaml): 8 IR sensors with Webots's curve,
        # 67.19 (the far end) where nothing is seen, more where something is.
        w = swarmsim.World(world("epuck_diffusion.yaml"), seed=3,
                           set={"robots": 200, "density": 20.0})
        w.step(5)
        d = w.proximity("epuck")
        v = w.proximity_values("epuck")
        self.assertEqual(v.shape, (200, 8))
        seen = np.isfinite(d)
        self.assertTrue(seen.any(), "in a dense swarm some sensor sees something")
        self.assertTrue(np.allclose(v[~seen], 67.19, atol=1e-3))
        self.assertTrue(np.all((v[seen] >= 67.19 - 1e-3) & (v[seen] <= 4095)))
        self.assertTrue((v[seen] > 100).any())
        # A foot-bot's rays have no curve: NaN.
        f = swarmsim.World(world("diffusion.yaml"), seed=3, set={"robots": 10})
        f.step(1)
        self.assertTrue(np.isnan(f.proximity_values("footbot")).all())

    def test_sensor_and_joint_arrays(self):
        w = swarmsim.World(world("diffusion.yaml"), seed=3, set={"robots": 200, "density": 4.0})
        self.assertEqual(w.sensor_names("footbot")[:2], ["prox[0]", "prox[1]"])
        self.assertEqual(w.joint_names("footbot"), ["leftMotor", "rightMotor"])
        w.step(5)
        d = w.proximity("footbot")
        self.assertEqual(d.shape, (200, 24))
        seen = np.isfinite(d)
        self.assertTrue(seen.any(), "in a dense swarm some sensor sees something")
        self.assertTrue((~seen).any())
        self.assertTrue(np.all((d[seen] >= 0) & (d[seen] <= 0.1 + 1e-9)))
        q = w.joint_velocities("footbot")
        self.assertEqual(q.shape, (200, 2))
        # The Lua controller drives each wheel at 0 or wheel_speed / radius.
        self.assertTrue(np.all(np.isclose(q, 0, atol=0.05) | np.isclose(q, 0.05 / 0.029, atol=0.05)))
        self.assertTrue(np.any(np.isclose(q, 0.05 / 0.029, atol=0.05)), "the wheels turn")
        self.assertTrue(np.any(np.isclose(q, 0, atol=0.05)), "robots near others turn on one wheel")

    def test_metrics(self):
        w = swarmsim.World(world("diffusion.yaml"), seed=1, set={"robots": 20})
        w.step(20)
        self.assertIn("mean_nearest_neighbor_distance", w.metrics)
        steps, values = w.metric_history("mean_nearest_neighbor_distance")
        self.assertEqual(list(steps), [10, 20])
        self.assertTrue(np.all(values > 0))
        self.assertEqual(values[-1], w.metrics["mean_nearest_neighbor_distance"])

    def test_describe(self):
        w = swarmsim.World(world("diffusion.yaml"), set={"robots": 12})
        text = w.describe()
        self.assertIn("model footbot", text)
        self.assertIn("12 copies", text)
        self.assertRegex(text, r"\n  script: \S*scripts/diffusion.lua on :")
        self.assertIn("12 copies, numbered along the region (order: spatial)", text)
        self.assertIn("\nLua states: 64 robots a state (simulation.robots_per_lua_state)\n", text)
        # What `swarmsim describe` prints, parameters' units and ranges included (it was
        # a shorter text of its own).
        code, out = run([BINARY, "describe", world("diffusion.yaml"), "--set", "robots=12"],
                        cwd=os.getcwd())  # paths shown as this process shows them
        self.assertEqual(code, 0, out)
        # Past the first line (the world file as each was given it).
        self.assertEqual(text.split("\n", 1)[1], out.split("\n", 1)[1])


class UrdfTest(unittest.TestCase):
    def test_package_path_resolves_a_urdfs_package_uris(self):
        # The example arm's URDF alone in a folder: its package:// mesh is found only
        # through package_path (the folder holding simple_arm_description).
        with tempfile.TemporaryDirectory() as d:
            urdf = ROOT / "worlds" / "models" / "simple_arm_description" / "urdf" / "simple_arm.urdf"
            with open(os.path.join(d, "arm.urdf"), "w") as f:
                f.write(urdf.read_text())
            path = os.path.join(d, "w.yaml")
            with open(path, "w") as f:
                f.write("simulation: {physics: ode, time_step: 0.05, seed: 1, steps: 10}\n"
                        "models:\n  - model: arm.urdf\n    position: [0, 0]\n")
            with self.assertRaises(ValueError) as e:
                swarmsim.World(path)
            self.assertIn("simple_arm_description", str(e.exception))
            w = swarmsim.World(path, package_path=[world("models")])
            self.assertFalse(w.planar)
            w.step(10)
            self.assertEqual(w.joint_positions().shape[0], 1)


if __name__ == "__main__":
    unittest.main()
