"""swarmsim.step_worlds: many worlds stepped together, each one ending where stepping it
alone ends (issue 30, part 6)."""

import unittest

import numpy as np

import swarmsim
from common import world

DIFFUSION = world("diffusion.yaml")


def make(seed, robots=12, **kwargs):
    return swarmsim.World(DIFFUSION, seed=seed, set={"robots": robots}, threads=1, **kwargs)


def turning(robots):
    # A controller that depends on what the robots sense, so a mix-up shows.
    seen = np.isfinite(robots.proximity).sum(axis=1)
    return {"leftMotor": 1.0 + 0.1 * seen, "rightMotor": 1.5 - 0.05 * seen}


class StepWorldsTest(unittest.TestCase):
    def test_each_world_ends_as_stepping_it_alone_at_any_thread_count(self):
        expected = []
        for seed in range(6):
            alone = make(seed, controllers={"footbot": turning} if seed % 2 else {})
            alone.step(15)
            expected.append(alone.state_hash())
        for threads in (1, 2, 4):
            worlds = [make(seed, controllers={"footbot": turning} if seed % 2 else {})
                      for seed in range(6)]
            swarmsim.step_worlds(worlds, 5, threads=threads)
            swarmsim.step_worlds(worlds, n=10, threads=threads)
            self.assertEqual([w.state_hash() for w in worlds], expected, f"threads={threads}")
            self.assertEqual([w.steps for w in worlds], [15] * 6)
        self.assertEqual(len(set(expected)), 6, "the seeds give different worlds")

    def test_ctrl_c_stops_every_world_soon_and_they_stay_usable(self):
        # Lua worlds never see Python's signals: step_worlds ran all its steps first.
        import os
        import signal
        import threading
        worlds = [make(seed, robots=30) for seed in range(2)]
        n = 20000
        timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
        with self.assertRaises(KeyboardInterrupt):
            timer.start()
            swarmsim.step_worlds(worlds, n, threads=2)
        timer.join()
        steps = [w.steps for w in worlds]
        self.assertTrue(all(0 < s < n for s in steps), steps)
        for w in worlds:
            w.step(1)  # usable after the interrupt
        self.assertEqual([w.steps for w in worlds], [s + 1 for s in steps])

    def test_metrics_are_taken_as_by_step(self):
        a, b = make(3), make(3)
        a.step(20)
        swarmsim.step_worlds([b], 20)
        for x, y in zip(a.metric_history("mean_nearest_neighbor_distance"),
                        b.metric_history("mean_nearest_neighbor_distance")):
            np.testing.assert_array_equal(x, y)
        self.assertEqual(len(b.metric_history("mean_nearest_neighbor_distance")[0]), 2)

    def test_a_failing_world_is_named_and_the_others_finish(self):
        def broken(robots):
            if robots.step == 3:
                raise ZeroDivisionError("boom")
            return None

        worlds = [make(1), make(2, controllers={"footbot": broken}), make(3)]
        with self.assertRaises(RuntimeError) as e:
            swarmsim.step_worlds(worlds, 8, threads=2)
        message = str(e.exception)
        self.assertIn("worlds[1]", message)
        self.assertIn("diffusion.yaml", message)
        self.assertIn("ZeroDivisionError", message)
        self.assertEqual([w.steps for w in worlds], [8, 3, 8])
        with self.assertRaises(RuntimeError) as again:
            swarmsim.step_worlds(worlds, 1)
        self.assertIn("worlds[1]", str(again.exception))
        self.assertIn("cannot be stepped again", str(again.exception))
        swarmsim.step_worlds([worlds[0], worlds[2]], 1)
        self.assertEqual(worlds[0].steps, 9)

    def test_a_controller_using_another_world_of_the_same_call_raises_not_hangs(self):
        # step_worlds holds every listed world's gate until all have stepped: a controller
        # that read or stepped another of them waited for ever (Ctrl-C could not stop it).
        # Run in a child with a timeout, so that a regression fails instead of hanging.
        script = """
import swarmsim
W = %r
for call in ("poses", "step"):
    other = swarmsim.World(W, set={"robots": 4}, threads=1)
    def ctl(robots, other=other, call=call):
        getattr(other, call)()
        return {}
    w = swarmsim.World(W, set={"robots": 4}, threads=1, controllers={"footbot": ctl})
    w.step()  # alone: reading or stepping another world is fine
    try:
        swarmsim.step_worlds([w, other], 1, threads=2)
    except RuntimeError as e:
        print(call, "raised:", e)
    print(call, "steps", w.steps, other.steps)
""" % DIFFUSION
        import subprocess
        import sys
        p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                           timeout=120)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        for call in ("poses", "step"):
            self.assertIn(f"{call} raised: step_worlds: worlds[0]", p.stdout)
        self.assertIn("a controller there may read only its own world", p.stdout)
        # The world whose controller failed stopped; the other stepped.
        self.assertIn("poses steps 1 1", p.stdout)

    def test_zero_steps_and_an_empty_list_do_nothing(self):
        w = make(1)
        swarmsim.step_worlds([w], 0)
        swarmsim.step_worlds([], 5)
        self.assertEqual(w.steps, 0)
        with self.assertRaises(ValueError):
            swarmsim.step_worlds([w], -1)


if __name__ == "__main__":
    unittest.main()
