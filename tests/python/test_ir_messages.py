"""IR messages (modules/ir_messaging, the Kilobot's) from Python: what each robot heard as flat
arrays with out= reuse, and queuing messages (README.md, "Python")."""

import os
import tempfile
import unittest

import numpy as np

import swarmsim

MODEL = """model: bot
objects:
  type: dummy
  children:
    - {name: ir, type: ir_transceiver, position: [0, 0, 0], range: 0.1, payload_size: 4,
       distance_noise: 0}
"""

# Robots 0 and 1 6 cm apart, robot 2 far away.
WORLD = """simulation: {physics: kinematic, time_step: 0.03125}
models:
  - {model: bot.yaml, position: [0, 0]}
  - {model: bot.yaml, position: [0.06, 0]}
  - {model: bot.yaml, position: [5, 5]}
"""


class IrMessagesTest(unittest.TestCase):
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

    def test_messages_heard_as_flat_arrays(self):
        w = self.world
        empty = w.ir_messages("bot")
        self.assertEqual(list(empty["offsets"]), [0, 0, 0, 0])
        self.assertEqual(empty["data"].shape, (0, 0))
        # Robot 0 sends 3 bytes, robot 2 sends 1 (nobody is near it).
        w.send_ir_messages("bot", [[7, 8, 9], [0, 0, 0], [5, 0, 0]], send=np.array([True, False, True]))
        w.step()
        m = w.ir_messages("bot")
        self.assertEqual(list(m["offsets"]), [0, 0, 1, 1])   # only robot 1 hears (robot 0)
        self.assertEqual(list(m["sender"]), [0])
        self.assertEqual(list(m["size"]), [3])
        self.assertEqual(m["data"].tolist(), [[7, 8, 9]])
        self.assertEqual(m["data"].dtype, np.uint8)
        self.assertAlmostEqual(m["distance"][0], 0.06, places=12)  # no distance noise here
        self.assertEqual(m["sent"].tolist(), [True, False, True])
        # A queue empties at the sense phase: the next step hears nothing.
        w.step()
        again = w.ir_messages("bot")
        self.assertEqual(list(again["offsets"]), [0, 0, 0, 0])
        self.assertEqual(again["sent"].tolist(), [False, False, False])

    def test_out_reuses_the_arrays_that_still_fit(self):
        w = self.world
        w.send_ir_messages("bot", [[1, 2], [3, 4], [5, 6]])
        w.step()
        first = w.ir_messages("bot")
        arrays = {k: v for k, v in first.items()}
        w.send_ir_messages("bot", [[9, 9], [8, 8], [7, 7]])
        w.step()
        second = w.ir_messages("bot", out=first)
        self.assertIs(second, first)
        for key in arrays:   # the same messages count and size: every array refilled in place
            self.assertIs(second[key], arrays[key], key)
        self.assertEqual(sorted(second["data"].tolist()), [[8, 8], [9, 9]])
        w.step()  # nothing sent: M = 0, so the per-message arrays are new; offsets and sent stay
        third = w.ir_messages("bot", out=first)
        self.assertIs(third["offsets"], arrays["offsets"])
        self.assertIs(third["sent"], arrays["sent"])
        self.assertEqual(third["distance"].shape, (0,))
        with self.assertRaises(TypeError):
            w.ir_messages("bot", out=np.zeros(4))

    def test_controllers_read_and_send_them(self):
        heard, steps = [], []

        def talk(robots):
            heard.append(robots.ir_messages["offsets"].copy())
            steps.append(robots.step)
            data = np.full((robots.count, 1), robots.step % 256)
            robots.send_ir_messages(data, send=np.arange(robots.count) == 0)  # robot 0 only
            return None

        self.world.close()
        w = self.world = swarmsim.World(os.path.join(self.dir.name, "world.yaml"),
                                        controllers={"bot": talk})
        w.step(3)
        self.assertEqual(list(heard[0]), [0, 0, 0, 0])
        self.assertEqual(list(heard[1]), [0, 0, 1, 1])   # robot 1 hears robot 0
        self.assertEqual(list(heard[2]), [0, 0, 1, 1])
        m = w.ir_messages("bot")
        self.assertEqual(m["sent"].tolist(), [True, False, False])
        self.assertEqual(m["data"].tolist(), [[steps[1] % 256]])  # queued in the second call

    def test_bad_messages_raise_and_queue_nothing(self):
        w = self.world
        for bad in ([[1, 2], [3, 4]], np.zeros((3, 0), dtype=int), [[1], [2], [256]],
                    [[1], [2], [-1]], np.zeros((3, 5), dtype=int)):
            with self.assertRaises(ValueError):
                w.send_ir_messages("bot", bad)
        # As set_range_and_bearing_data: whole floats are bytes (np.zeros makes
        # floats), fractions and booleans are not.
        with self.assertRaisesRegex(ValueError, r"IR messages must be bytes, whole numbers "
                                                r"0..255 \(got 1.5\)"):
            w.send_ir_messages("bot", np.full((3, 2), 1.5))
        with self.assertRaisesRegex(TypeError, "IR messages is booleans"):
            w.send_ir_messages("bot", np.ones((3, 2), dtype=bool))
        with self.assertRaisesRegex(TypeError, "not dtype <U1"):
            w.send_ir_messages("bot", [["a"], ["b"], ["c"]])
        with self.assertRaises(ValueError):
            w.send_ir_messages("bot", np.zeros((3, 2), dtype=int), send=np.array([1, 0, 1]))
        with self.assertRaisesRegex(ValueError, "payload_size"):
            w.send_ir_messages("bot", np.zeros((3, 5), dtype=int))
        w.step()
        self.assertEqual(w.ir_messages("bot")["sent"].tolist(), [False, False, False])
        w.send_ir_messages("bot", np.full((3, 2), 7.0))
        w.step()
        self.assertEqual(w.ir_messages("bot")["sent"].tolist(), [True, True, True])
        with self.assertRaisesRegex(ValueError, "no IR transceiver 'eye'"):
            w.ir_messages("bot", transceiver="eye")


if __name__ == "__main__":
    unittest.main()
