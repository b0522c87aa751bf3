"""Ground sensors as numpy arrays (README.md, "Python"): World.ground() and a
controller's robots.ground, one column per ground sensor in the model's order."""

import pathlib
import tempfile
import unittest

import numpy as np

import swarmsim
from common import world

EYES = """model: eyes
objects:
  type: dummy
  children:
    - {type: ground_array, name: g, points: [[0.1, 0], [-0.1, 0]]}
    - {name: b, type: ground_sensor, mode: binary, threshold: 0.4}
"""

# A floor whose x < 0 half is black, x >= 0 half red; robots facing +x.
WORLD = """simulation: {physics: kinematic, steps: 5}
arena: {size: 4}
floor:
  background: 1
  shapes: [{type: rectangle, min: [-2, -2], max: [0, 2], color: 0},
           {type: rectangle, min: [0, -2], max: [2, 2], color: [1, 0, 0]}]
models:
  - {model: eyes.yaml, position: [-1, 0, 0]}
  - {model: eyes.yaml, position: [0.05, 1, 0]}
  - {model: eyes.yaml, position: [1, -1, 0]}
"""


class GroundTest(unittest.TestCase):
    def test_world_ground_reads_each_sensor_under_each_robot(self):
        with tempfile.TemporaryDirectory() as folder:
            pathlib.Path(folder, "eyes.yaml").write_text(EYES)
            pathlib.Path(folder, "w.yaml").write_text(WORLD)
            w = swarmsim.World(str(pathlib.Path(folder, "w.yaml")))
            self.assertEqual(w.ground_names("eyes"), ["g[0]", "g[1]", "b"])
            np.testing.assert_array_equal(w.ground(), np.zeros((3, 3)))  # not sensed yet
            w.step()
            red = 0.299  # the grey level of [1, 0, 0]
            np.testing.assert_array_equal(
                w.ground("eyes"),
                [[0, 0, 0],        # all on black
                 [red, 0, 0],      # g[0] at x = 0.15 on red, g[1] at -0.05 on black, b at 0.05: 0.299 < 0.4
                 [red, red, 0]])
            out = np.empty((3, 3))
            w.ground(out=out)
            np.testing.assert_array_equal(out, w.ground())

    def test_a_controller_sees_the_same_columns(self):
        seen = []

        def control(robots):
            seen.append((list(robots.ground_names), robots.ground.copy()))
            return {}

        with tempfile.TemporaryDirectory() as folder:
            pathlib.Path(folder, "eyes.yaml").write_text(EYES)
            pathlib.Path(folder, "w.yaml").write_text(WORLD)
            w = swarmsim.World(str(pathlib.Path(folder, "w.yaml")), controllers={"eyes": control})
            w.step(2)
        self.assertEqual(seen[1][0], ["g[0]", "g[1]", "b"])
        np.testing.assert_array_equal(seen[1][1][:, 2], [0, 0, 0])
        self.assertEqual(seen[1][1][2, 0], 0.299)

    def test_the_example_world_has_four_motor_ground_sensors(self):
        w = swarmsim.World(world("ground_nest.yaml"))
        w.step()
        g = w.ground("nestbot")
        self.assertEqual(g.shape, (20, 4))
        # The robots start on the pale checkerboard (grey 0.8 to 0.95, noise 0.02).
        self.assertTrue(((g > 0.7) & (g <= 1)).all(), g)


if __name__ == "__main__":
    unittest.main()
