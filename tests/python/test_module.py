"""swarmsim's Python module (swarm/python/module.cc): a world that does not load, misuse,
and `python -m swarmsim` (README.md, "Python"). World itself: test_world.py."""

import os
import tempfile
import unittest

import numpy as np

import swarmsim
from common import BINARY, PYTHON, run, world


class ErrorTest(unittest.TestCase):
    def test_a_world_that_does_not_load_raises_with_the_programs_message(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "bad.yaml")
            with open(path, "w") as f:
                f.write("simulation:\n  physics: box2d\n  tim_step: 0.1\n")
            with self.assertRaises(ValueError) as e:
                swarmsim.World(path)
            self.assertIn("bad.yaml:3:3", str(e.exception))
            self.assertIn("time_step", str(e.exception))  # the suggestion
        with self.assertRaises(ValueError) as e:
            swarmsim.World("/no/such/world.yaml")
        self.assertIn("/no/such/world.yaml", str(e.exception))
        with self.assertRaises(ValueError) as e:
            swarmsim.World(world("diffusion.yaml"), set={"robotz": 3})
        self.assertIn("robotz", str(e.exception))

    def test_misuse_raises_instead_of_crashing(self):
        w = swarmsim.World(world("diffusion.yaml"), set={"robots": 10})
        with self.assertRaises(ValueError):
            w.poses(out=np.empty((10, 3), dtype=np.float32))
        with self.assertRaises(ValueError):
            w.poses(out=np.empty((11, 3)))
        with self.assertRaises(ValueError):
            w.poses(out=np.empty((3, 10)).T)
        with self.assertRaises(ValueError):
            w.step(-1)
        with self.assertRaises(ValueError):
            w.poses("no_such_model")
        with self.assertRaises(ValueError):
            w.set_joint_targets("footbot", {"leftMotor": np.zeros(3)})
        with self.assertRaises(ValueError):
            w.set_joint_targets("footbot", {"noMotor": np.zeros(10)})
        with self.assertRaises(TypeError):
            swarmsim.World(world("diffusion.yaml"), controllers={"footbot": 3})
        w.close()
        with self.assertRaises(RuntimeError):
            w.step()
        with self.assertRaises(RuntimeError):
            w.poses()


class ProgramTest(unittest.TestCase):
    def test_the_program_refuses_a_python_world_and_says_how_to_run_it(self):
        code, out = run([BINARY, "run", world("python", "diffusion_numpy.yaml"), "--steps", "2"])
        self.assertEqual(code, 2, out)
        self.assertIn("diffusion_numpy.yaml:26:5", out)
        self.assertIn("python3 -m swarmsim run", out)

    def test_python_m_swarmsim_run(self):
        env = {"PYTHONPATH": os.pathsep.join(filter(None, [os.environ.get("PYTHONPATH")]))}
        code, out = run([PYTHON, "-m", "swarmsim", "run", world("python", "diffusion_numpy.yaml"),
                         "--steps", "10", "--set", "robots=20", "--hash"], env)
        self.assertEqual(code, 0, out)
        self.assertRegex(out, r"state-hash: [0-9a-f]{16}")
        code, out = run([PYTHON, "-m", "swarmsim", "run", "/no/such.yaml"], env)
        self.assertEqual(code, 2, out)
        self.assertIn("/no/such.yaml", out)


if __name__ == "__main__":
    unittest.main()
