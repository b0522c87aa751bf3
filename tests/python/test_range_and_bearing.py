"""Range-and-bearing boards from Python (swarm/python/arrays.cc): what each robot
heard as flat arrays, and setting what each robot sends (README.md, "Python")."""

import math
import os
import tempfile
import unittest

import numpy as np

import swarmsim

MODEL = """model: bot
objects:
  type: dummy
  children:
    - {name: rab, type: range_and_bearing, position: [0, 0, 0.1], range: 1.5, payload_size: 4}
"""

# Robot 0 at the origin facing +y; robot 1 1 m east of it; robot 2 far away.
WORLD = """simulation: {physics: kinematic, time_step: 0.1}
models:
  - {model: bot.yaml, position: [0, 0], heading_deg: 90}
  - {model: bot.yaml, position: [1, 0]}
  - {model: bot.yaml, position: [10, 10]}
"""


class RangeAndBearingTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        with open(os.path.join(self.dir.name, "bot.yaml"), "w") as f:
            f.write(MODEL)
        with open(os.path.join(self.dir.name, "world.yaml"), "w") as f:
            f.write(WORLD)
        self.world = swarmsim.World(os.path.join(self.dir.name, "world.yaml"))

    def tearDown(self):
        self.world.close()
        self.dir.cleanup()

    def test_readings_and_data(self):
        w = self.world
        w.set_range_and_bearing_data("bot", np.array([[1, 2], [3, 4], [5, 6]]))
        w.step(1)
        r = w.range_and_bearing("bot")
        self.assertEqual(list(r["offsets"]), [0, 1, 2, 2])  # robot 2 hears no one
        # Robot 0 faces +y: robot 1 (east) is on its right, bearing -pi/2.
        self.assertAlmostEqual(r["range"][0], 1.0, places=12)
        self.assertAlmostEqual(r["bearing"][0], -math.pi / 2, places=12)
        self.assertAlmostEqual(r["elevation"][0], 0.0, places=12)
        self.assertEqual(list(r["sender"]), [1, 0])
        self.assertEqual(r["data"].shape, (2, 4))
        self.assertEqual(r["data"].tolist(), [[3, 4, 0, 0], [1, 2, 0, 0]])
        # Robot 1 faces +x: robot 0 is behind it.
        self.assertAlmostEqual(r["bearing"][1], math.pi, places=12)

    def test_bad_data_is_a_value_error(self):
        w = self.world
        with self.assertRaisesRegex(ValueError, "more than robot 'bot#0''s payload_size"):
            w.set_range_and_bearing_data("bot", np.zeros((3, 5)))
        with self.assertRaisesRegex(ValueError, "0..255"):
            w.set_range_and_bearing_data("bot", np.full((3, 1), 256))
        with self.assertRaisesRegex(ValueError, r"shape \(3, bytes\)"):
            w.set_range_and_bearing_data("bot", np.zeros((2, 1)))
        # Fractions and NaN are not cut to bytes in silence; booleans are not bytes.
        with self.assertRaisesRegex(ValueError, r"whole numbers 0..255 \(got 1.7\)"):
            w.set_range_and_bearing_data("bot", np.full((3, 1), 1.7))
        with self.assertRaisesRegex(ValueError, r"whole numbers 0..255 \(got nan\)"):
            w.set_range_and_bearing_data("bot", np.full((3, 1), np.nan))
        with self.assertRaisesRegex(TypeError, "booleans, not bytes"):
            w.set_range_and_bearing_data("bot", np.ones((3, 1), dtype=bool))
        with self.assertRaisesRegex(TypeError, "not dtype <U1"):
            w.set_range_and_bearing_data("bot", [["a"], ["b"], ["c"]])
        # Whole floats (np.zeros makes floats) are bytes.
        w.set_range_and_bearing_data("bot", np.array([[7.0], [8.0], [255.0]]))
        w.step(1)
        self.assertEqual(w.range_and_bearing("bot")["data"][:, 0].tolist(), [8, 7])


if __name__ == "__main__":
    unittest.main()
