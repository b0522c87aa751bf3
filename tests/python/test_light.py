"""Light sensors as numpy arrays (modules/light; worlds/README.md "light_sensor")."""

import unittest

import numpy as np

import swarmsim
from common import world


class LightArraysTest(unittest.TestCase):
    def test_light_array_matches_the_lamp(self):
        w = swarmsim.World(world("phototaxis.yaml"), seed=1)
        names = w.light_sensor_names("photobot")
        self.assertEqual(names, [f"light[{i}]" for i in range(8)])
        self.assertEqual(w.light("photobot").shape, (20, 8))
        self.assertTrue(np.all(w.light("photobot") == 0), "nothing read before the first step")
        p = w.poses("photobot")  # what the first step's sense phase sees
        w.step(1)
        r = w.light("photobot")
        self.assertTrue(np.all(r >= 0))
        # Every robot not in the pillar's shadow reads the lamp on some sensor,
        # most on the one facing it: the sensor whose axis is nearest the
        # lamp's bearing in the robot's frame (the lamp at (1.2, 1.2)), for
        # robots whose bearing is not near halfway between two sensors.
        bearing = np.mod(np.arctan2(1.2 - p[:, 1], 1.2 - p[:, 0]) - p[:, 2], 2 * np.pi)
        nearest = np.rint(bearing / (np.pi / 4)).astype(int) % 8
        off_middle = np.abs(np.mod(bearing, np.pi / 4) - np.pi / 8) > np.radians(5)
        # Robots whose line to the lamp passes near the pillar (radius 0.2 at
        # (0.3, 0.3)) may have some sensors in its shadow: left out.
        a = p[:, :2]
        v = np.array([1.2, 1.2]) - a
        t = np.clip(np.sum((np.array([0.3, 0.3]) - a) * v, axis=1) / np.sum(v * v, axis=1), 0, 1)
        clear = np.linalg.norm(a + t[:, None] * v - np.array([0.3, 0.3]), axis=1) > 0.35
        lit = r.max(axis=1) > 0
        self.assertGreater(lit.sum(), 10)
        self.assertTrue(np.all(lit[clear]), "robots in clear view read the lamp")
        self.assertFalse(np.all(lit), "robots behind the pillar do not")
        keep = clear & off_middle
        self.assertGreater(keep.sum(), 8)
        self.assertTrue(np.all(r[keep].argmax(axis=1) == nearest[keep]))
        # Switched off through a parameter: nothing to read.
        dark = swarmsim.World(world("phototaxis.yaml"), seed=1, set={"intensity": 0})
        dark.step(1)
        self.assertTrue(np.all(dark.light("photobot") == 0))
        out = np.empty((20, 8))
        self.assertIs(w.light("photobot", out=out), out)
        np.testing.assert_array_equal(out, r)

    def test_controller_sees_light(self):
        seen = []

        def control(robots):
            seen.append((robots.light.shape, list(robots.light_sensor_names)))

        w = swarmsim.World(world("phototaxis.yaml"), seed=1, controllers={"photobot": control})
        w.step(2)
        self.assertEqual(seen[-1][0], (20, 8))
        self.assertEqual(seen[-1][1][0], "light[0]")


if __name__ == "__main__":
    unittest.main()
