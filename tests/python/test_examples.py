"""The Python examples in scripts/ run as their docstrings say."""

import os
import re
import sqlite3
import sys
import tempfile
import unittest

import numpy as np

from common import BINARY, PYTHON, ROOT, run, world

sys.path.insert(0, str(ROOT / "scripts"))
import diffusion_env  # noqa: E402
import sweep_analysis  # noqa: E402


class DiffusionEnvTest(unittest.TestCase):
    def test_reset_and_step_return_arrays_and_are_reproducible(self):
        env = diffusion_env.DiffusionEnv(robots=20, episode_steps=5)
        obs = env.reset(seed=3)
        self.assertEqual(obs.shape, (20, 26))
        actions = np.tile([0.05, 0.05], (20, 1))
        trace, hashes = [], []
        for _ in range(5):
            obs, rewards, dones = env.step(actions)
            self.assertEqual(rewards.shape, (20,))
            self.assertEqual(dones.dtype, bool)
            trace.append(obs.copy())
            hashes.append(env.world.state_hash())
        self.assertTrue(dones.all(), "the episode ends after episode_steps")
        # Straight at 0.05 m/s for 0.1 s: about 5 mm a step where nothing is close.
        self.assertAlmostEqual(float(np.median(rewards)), 0.005, delta=0.001)
        env.reset(seed=3)
        for step, expected in enumerate(trace):
            again, _, _ = env.step(actions)
            self.assertEqual(env.world.state_hash(), hashes[step], f"step {step + 1}")
            where = np.argwhere(again != expected)
            self.assertEqual(len(where), 0,
                             f"step {step + 1}: observations differ at (robot, column) "
                             f"{where[:5].tolist()}: {again[tuple(where[0])]!r} against "
                             f"{expected[tuple(where[0])]!r}" if len(where) else "")
        with self.assertRaises(ValueError):
            env.step(np.zeros((3, 2)))
        env.close()

    def test_the_script_runs(self):
        code, out = run([PYTHON, str(ROOT / "scripts" / "diffusion_env.py"), "--robots", "10",
                         "--steps", "5"])
        self.assertEqual(code, 0, out)
        self.assertIn("10 robots, 5 steps: mean return", out)


class SweepAnalysisTest(unittest.TestCase):
    def test_reads_a_sweep_database(self):
        with tempfile.TemporaryDirectory() as d:
            db = os.path.join(d, "s.db")
            code, out = run([BINARY, "sweep", world("diffusion.yaml"), "--param", "robots=10,20",
                             "--seeds", "2", "--steps", "20", "--db", db, "--quiet"])
            self.assertEqual(code, 0, out)
            table = sweep_analysis.summarise(db, "robots", "mean_nearest_neighbor_distance")
            self.assertEqual([(v, n) for v, n, _, _ in table], [("10", 2), ("20", 2)])
            # Independently: the mean of the database's own values.
            con = sqlite3.connect(db)
            expected = con.execute(
                "SELECT avg(m.value) FROM final_metrics m JOIN run_params p ON p.run = m.run "
                "WHERE p.name = 'robots' AND p.value = '10' AND m.metric = "
                "'mean_nearest_neighbor_distance'").fetchone()[0]
            con.close()
            self.assertAlmostEqual(table[0][2], expected)
            code, out = run([PYTHON, str(ROOT / "scripts" / "sweep_analysis.py"), db, "--param",
                             "robots", "--metric", "mean_nearest_neighbor_distance"])
            self.assertEqual(code, 0, out)
            self.assertRegex(out, r"\n10\t2\t[0-9.e-]+\t")
            code, out = run([PYTHON, str(ROOT / "scripts" / "sweep_analysis.py"), db, "--param",
                             "robots", "--metric", "nope"])
            self.assertEqual(code, 2, out)
            self.assertIn("no finished run", out)


if __name__ == "__main__":
    unittest.main()
