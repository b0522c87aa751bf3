"""Kilobot programs (swarm/kilobot) under Python's World: one process, several worlds."""

import os
import tempfile
import unittest

import swarmsim
from common import BINARY, ROOT, run

# Robot 0's main() never returns; any other robot's does.
HANG_ON_ZERO = r"""#include <kilolib.h>
volatile int x;
void setup() {}
void loop() {}
int main() {
  kilo_init();
  if (kilo_uid == 0) for (;;) x++;
  kilo_start(setup, loop);
  return 0;
}
"""


class KilobotWorldsTest(unittest.TestCase):
    def test_a_hang_in_one_world_is_not_the_next_worlds(self):
        # A main() that timed out made every later main() of the program
        # refuse to run, in any world the process loaded after it.
        with tempfile.TemporaryDirectory() as d:
            with open(os.path.join(d, "hang0.c"), "w") as f:
                f.write(HANG_ON_ZERO)
            code, out = run([BINARY, "kilobot", "build", os.path.join(d, "hang0.c")])
            self.assertEqual(code, 0, out)
            path = os.path.join(d, "world.yaml")
            with open(path, "w") as f:
                f.write("plugins: [hang0]\n"
                        "simulation: {physics: planar, time_step: 0.03125}\n"
                        "arena: {size: 0.5}\n"
                        "models:\n"
                        "  - model: " + str(ROOT / "worlds" / "models" / "kilobot.yaml") + "\n"
                        "    count: 2\n"
                        "    distribute: {region: arena}\n"
                        "    parameters: {program_timeout: 0.5}\n"
                        "    native_controller: hang0\n")
            first = swarmsim.World(path, threads=1)
            with self.assertRaisesRegex(RuntimeError, "robot 0: main\\(\\) did not return"):
                first.step(2)
            first.close()
            second = swarmsim.World(path, threads=1, set={"kilobot.kilo_uid": 7})
            second.step(3)  # raised "main() not called: on robot 0 it did not return"
            self.assertEqual(second.steps, 3)
            second.close()


if __name__ == "__main__":
    unittest.main()
