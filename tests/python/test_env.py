"""swarmsim.env (swarm/python/swarmsim/env.py): the multi-agent environments, checked against
the API rules PettingZoo documents for Parallel environments and Gymnasium for vector
environments (neither library is installed here: the rules are written out below), and
swarmsim.spaces' Box."""

import importlib.util
import math
import os
import unittest
import warnings

import numpy as np

import swarmsim
from common import world
from swarmsim import env as senv
from swarmsim import spaces

DIFFUSION = world("python", "diffusion_numpy.yaml")
DT = 0.1  # s, the world's time step


def make(robots=6, **kw):
    kw.setdefault("set", {})
    kw["set"] = {"robots": robots, **kw["set"]}
    return senv.ParallelEnv(DIFFUSION, **kw)


def random_actions(env, rng):
    return {a: rng.uniform(-0.1, 0.1, size=2) for a in env.agents}


def check_parallel_api(test, env, seed, steps=40):
    """PettingZoo's documented rules for a Parallel environment (its parallel_api_test):
    reset returns (observations, infos) keyed by env.agents; every step returns five dicts
    keyed by the agents that were live before it; agents that terminated or truncated leave
    env.agents and never come back; every agent is one of possible_agents; num_agents is
    len(agents); observations lie in observation_space(agent); each space is the same
    object every time."""
    obs, infos = env.reset(seed=seed)
    test.assertIsInstance(obs, dict)
    test.assertIsInstance(infos, dict)
    test.assertEqual(set(obs), set(env.agents))
    test.assertEqual(set(infos), set(env.agents))
    test.assertTrue(set(env.agents) <= set(env.possible_agents))
    for a in env.agents:
        test.assertIs(env.observation_space(a), env.observation_space(a))
        test.assertIs(env.action_space(a), env.action_space(a))
        test.assertTrue(env.observation_space(a).contains(obs[a]), (a, obs[a]))
    finished = set()
    for _ in range(steps):
        if not env.agents:
            break
        live = list(env.agents)
        actions = {a: env.action_space(a).sample() for a in live}
        obs, rewards, terminations, truncations, infos = env.step(actions)
        for d in (obs, rewards, terminations, truncations, infos):
            test.assertEqual(set(d), set(live))
        for a in live:
            test.assertTrue(env.observation_space(a).contains(obs[a]), (a, obs[a]))
            test.assertIsInstance(rewards[a], float)
            test.assertIsInstance(terminations[a], bool)
            test.assertIsInstance(truncations[a], bool)
        now_done = {a for a in live if terminations[a] or truncations[a]}
        finished |= now_done
        test.assertEqual(set(env.agents), set(live) - now_done)
        test.assertFalse(set(env.agents) & finished, "an agent came back")
        test.assertEqual(env.num_agents, len(env.agents))
        test.assertTrue(set(env.agents) <= set(env.possible_agents))
    return finished


class ParallelApiTest(unittest.TestCase):
    def test_the_documented_parallel_api_rules_hold_over_an_episode(self):
        env = make(6, max_steps=15)
        self.assertEqual(env.possible_agents, [f"footbot#{i}" for i in range(6)])
        self.assertEqual(env.agents, [])  # before reset
        finished = check_parallel_api(self, env, seed=4)
        # Truncated at 15 steps: every agent finished, env.agents is empty.
        self.assertEqual(finished, set(env.possible_agents))
        self.assertEqual(env.agents, [])
        self.assertIsNone(env.render())
        self.assertIn("render_modes", env.metadata)
        env.close()

    def test_the_rules_hold_when_agents_terminate_one_by_one(self):
        # Agent i leaves at step i + 1.
        def terminate(world, agents):
            return np.arange(len(agents.names)) < agents.step
        env = make(5, terminate=terminate, max_steps=None)
        finished = check_parallel_api(self, env, seed=2, steps=10)
        self.assertEqual(finished, set(env.possible_agents))
        env.close()

    def test_spaces_follow_the_declarations(self):
        env = make(4, observations=["proximity", "pose", "joint_velocities"])
        space = env.observation_space("footbot#0")
        self.assertEqual(space.shape, (24 + 4 + 2,))
        self.assertEqual(space.dtype, np.float64)
        np.testing.assert_array_equal(space.low[:24], 0.0)
        np.testing.assert_array_equal(space.high[:24], 1.0)
        np.testing.assert_array_equal(space.low[26:28], -1.0)  # cos, sin of the heading
        self.assertEqual(space.high[24], np.inf)  # x is unbounded
        action = env.action_space("footbot#0")
        self.assertEqual(action.shape, (2,))
        np.testing.assert_array_equal(action.low, [-0.1, -0.1])
        np.testing.assert_array_equal(action.high, [0.1, 0.1])
        self.assertEqual(env.joint_names, ["leftMotor", "rightMotor"])
        # state(): every agent's observation in one row, in state_space.
        obs, _ = env.reset(seed=3)
        state = env.state()
        self.assertEqual(env.state_space.shape, (4 * 30,))
        self.assertEqual(state.shape, env.state_space.shape)
        np.testing.assert_array_equal(state[30:60], obs["footbot#1"])
        np.testing.assert_array_equal(env.state_space.low[30:60], space.low)
        self.assertTrue(env.state_space.contains(state))
        env.close()


class DeterminismTest(unittest.TestCase):
    def run_episode(self, seed, threads=0, steps=8):
        env = make(8, threads=threads)
        obs, _ = env.reset(seed=seed)
        frames = [np.stack([obs[a] for a in env.possible_agents])]
        rng = np.random.default_rng(99)
        for _ in range(steps):
            obs, rewards, *_ = env.step(random_actions(env, rng))
            frames.append(np.stack([obs[a] for a in env.possible_agents]))
            frames.append(np.array([rewards[a] for a in env.possible_agents])[:, None])
        env.close()
        return frames

    def assert_same(self, a, b):
        self.assertEqual(len(a), len(b))
        for x, y in zip(a, b):
            self.assertEqual(x.tobytes(), y.tobytes())

    def test_same_seed_same_observations_at_any_thread_count(self):
        first = self.run_episode(11, threads=1)
        self.assert_same(first, self.run_episode(11, threads=1))
        self.assert_same(first, self.run_episode(11, threads=2))
        # Another seed places the robots elsewhere: the seed is used.
        other = self.run_episode(12, threads=1)
        self.assertNotEqual(first[0].tobytes(), other[0].tobytes())

    def test_a_reset_after_an_episode_starts_as_a_new_environment_does(self):
        env = make(8)
        env.reset(seed=5)
        rng = np.random.default_rng(1)
        for _ in range(6):
            env.step(random_actions(env, rng))
        again, _ = env.reset(seed=5)
        fresh_env = make(8)
        fresh, _ = fresh_env.reset(seed=5)
        for a in env.possible_agents:
            self.assertEqual(again[a].tobytes(), fresh[a].tobytes())
        self.assertEqual(env.world.state_hash(), fresh_env.world.state_hash())
        env.close()
        fresh_env.close()

    def test_a_seeded_reset_is_the_world_loaded_with_that_seed(self):
        # Whether the environment resets the World in place (World.reset) or loads it again,
        # the episode starts as a World loaded with the seed and stepped once with the
        # wheels still.
        env = make(8, observations=["proximity_distance", "pose"])
        env.reset(seed=21)
        env.step({a: np.full(2, 0.05) for a in env.agents})
        obs, _ = env.reset(seed=22)
        still = {"footbot": lambda robots: {"leftMotor": 0.0, "rightMotor": 0.0}}
        w = swarmsim.World(DIFFUSION, seed=22, set={"robots": 8}, controllers=still)
        w.step()
        self.assertEqual(env.world.state_hash(), w.state_hash())
        prox, poses = w.proximity("footbot"), w.poses("footbot")
        for i, a in enumerate(env.possible_agents):
            np.testing.assert_array_equal(obs[a][:24], prox[i])
            np.testing.assert_array_equal(obs[a][24:26], poses[i, :2])
        w.close()
        env.close()

    def test_a_world_that_cannot_reset_in_place_is_loaded_again_with_a_warning(self):
        from unittest import mock
        from swarmsim import _env_core

        class NoReset(swarmsim.World):
            def reset(self, seed=None):
                raise RuntimeError("snapshot: a module cannot save its state")
        plain = make(5)
        expected, _ = plain.reset(seed=2)
        plain.close()
        with mock.patch.object(_env_core, "World", NoReset):
            env = make(5)
            with self.assertWarnsRegex(RuntimeWarning, "World.reset failed.*cannot save"):
                obs, _ = env.reset(seed=2)
            self.assertEqual(env._core.reset_failures, 1)
            for a in env.possible_agents:
                self.assertEqual(obs[a].tobytes(), expected[a].tobytes())
            env.close()

    def test_resets_without_a_seed_draw_reproducible_new_episodes(self):
        def starts():
            env = make(6)
            out = [env.reset(seed=3)[0], env.reset()[0], env.reset()[0]]
            env.close()
            return [np.stack([o[a] for a in sorted(o)]) for o in out]
        a, b = starts(), starts()
        for x, y in zip(a, b):
            self.assertEqual(x.tobytes(), y.tobytes())
        self.assertNotEqual(a[1].tobytes(), a[2].tobytes())

    def test_the_first_reset_without_a_seed_uses_the_world_files(self):
        env = make(6)
        obs, _ = env.reset()
        env2 = make(6)
        obs2, _ = env2.reset(seed=1)  # diffusion_numpy.yaml's seed
        for a in env.possible_agents:
            self.assertEqual(obs[a].tobytes(), obs2[a].tobytes())
        env.close()
        env2.close()


class ActionTest(unittest.TestCase):
    def test_actions_are_wheel_speeds_in_metres_per_second(self):
        # One robot alone in a 3 m arena, driving straight at 0.05 m/s: 5 mm a step,
        # which the distance reward (the default) reports.
        env = senv.ParallelEnv(DIFFUSION, set={"robots": 1, "density": 0.1})
        env.reset(seed=1)
        total = 0.0
        for _ in range(10):
            _, rewards, *_ = env.step({"footbot#0": np.array([0.05, 0.05])})
            total += rewards["footbot#0"]
        self.assertAlmostEqual(total, 10 * 0.05 * DT, delta=0.1 * 10 * 0.05 * DT)
        np.testing.assert_allclose(env.world.joint_velocities("footbot")[0], 0.05 / 0.029,
                                   rtol=0.02)
        # Standing still: no distance.
        _, rewards, *_ = env.step({"footbot#0": np.zeros(2)})
        _, rewards, *_ = env.step({"footbot#0": np.zeros(2)})
        self.assertLess(rewards["footbot#0"], 1e-4)
        env.close()

    def test_actions_outside_the_space_are_refused_naming_the_agent(self):
        env = make(3)
        env.reset(seed=1)
        ok = {a: np.zeros(2) for a in env.agents}
        for bad, pattern in [
                (np.array([0.2, 0.0]), r"'footbot#1'.*outside the action space.*-0\.1, 0\.1"),
                # NaN: no hint to clip (clip_actions=True refuses it too).
                (np.array([np.nan, 0.0]), r"'footbot#1'.*outside.*\(NaN is refused with "
                                          r"clip_actions=True too\)"),
                (np.array([0.0, 0.0, 0.0]), r"'footbot#1' has shape \(3,\)"),
                (np.array([True, False]), r"real numbers"),
                (np.array([0j, 0j]), r"real numbers"),
                ("go", r"'footbot#1' must be real numbers, got dtype <U2")]:
            with self.assertRaisesRegex(ValueError, pattern):
                env.step({**ok, "footbot#1": bad})
        with self.assertRaisesRegex(ValueError, r"no action for agent 'footbot#2'"):
            env.step({"footbot#0": np.zeros(2), "footbot#1": np.zeros(2)})
        with self.assertRaisesRegex(KeyError, r"no agent 'robot#9'"):
            env.step({**ok, "robot#9": np.zeros(2)})
        with self.assertRaises(TypeError):
            env.step([np.zeros(2)] * 3)
        # A refused step did not step the world.
        self.assertEqual(env.world.steps, 1)
        # float32 policies: float32(0.1) is inside [-0.1, 0.1].
        env.step({a: np.full(2, 0.1, dtype=np.float32) for a in env.agents})
        env.step({**ok, "footbot#0": np.full(2, 0.1, dtype=np.float32)})  # mixed dtypes
        env.close()

    def test_clip_actions_clips_to_the_bounds(self):
        def run(action, clip):
            env = make(3, clip_actions=clip)
            env.reset(seed=2)
            for _ in range(3):
                obs, *_ = env.step({a: np.array(action) for a in env.agents})
            h = env.world.state_hash()
            env.close()
            return h
        self.assertEqual(run([0.5, -3.0], True), run([0.1, -0.1], False))

    def test_clip_actions_clips_infinities_too(self):
        # +-inf is a value past a bound like any other (it was refused as not finite).
        env = make(3, clip_actions=True)
        env.reset(seed=2)
        env.step({a: np.array([np.inf, -np.inf]) for a in env.agents})
        with self.assertRaisesRegex(ValueError, "is not finite"):
            env.step({a: np.array([np.nan, 0.0]) for a in env.agents})
        env.close()

    def test_a_step_whose_observation_raises_counts_towards_max_steps(self):
        # It did not: the episode ran max_steps + 1 world steps.
        failed = []

        def flaky(world, model):
            if world.steps == 3 and not failed:  # after the second step (the reset's is 1)
                failed.append(True)
                raise RuntimeError("obs fails once")
            return world.poses(model)[:, :2]
        env = make(2, observations=[senv.Observation("xy", flaky)], max_steps=4)
        env.reset(seed=1)
        env.step({a: np.zeros(2) for a in env.agents})
        with self.assertRaisesRegex(RuntimeError, "obs fails once"):
            env.step({a: np.zeros(2) for a in env.agents})
        env.step({a: np.zeros(2) for a in env.agents})
        *_, truncated, _ = env.step({a: np.zeros(2) for a in env.agents})
        self.assertTrue(all(truncated.values()), "the fourth world step ends the episode")
        self.assertEqual(env.world.steps, 1 + 4)  # the reset's step, then four
        env.close()

    def test_an_environment_is_not_copied_and_frees_its_worlds_when_dropped(self):
        import copy
        import gc
        import pickle
        import weakref
        env = make(2)
        env.reset(seed=1)
        # A deep copy's worlds reported to the original: every agent ended at its first
        # step with reward 0, and nothing was said.
        for what, call in (("copied", lambda: copy.deepcopy(env)),
                           ("copied", lambda: copy.copy(env)),
                           ("pickled", lambda: pickle.dumps(env))):
            with self.assertRaisesRegex(TypeError, f"ParallelEnv cannot be {what}"):
                call()
        vector = senv.VectorEnv(DIFFUSION, 2, set={"robots": 2})
        with self.assertRaisesRegex(TypeError, "VectorEnv cannot be copied"):
            copy.deepcopy(vector)
        # Dropped without close(): its worlds go with it (the controller the World holds
        # kept the environment, and so the World, alive for good).
        cores = [weakref.ref(env._core), weakref.ref(vector._core)]
        del env, vector
        gc.collect()
        self.assertEqual([c() for c in cores], [None, None])

    def test_a_vector_reset_seed_past_the_largest_is_refused_before_any_reset(self):
        # s + k past 2**64 - 1 reset environment 0 and not the others, and named a seed
        # nobody passed.
        vector = senv.VectorEnv(DIFFUSION, 3, set={"robots": 2})
        vector.reset(seed=5)
        vector.step(np.zeros((3, 2, 2)))
        with self.assertRaisesRegex(ValueError, r"reset: seed 18446744073709551615 gives "
                                                r"environment 2 the seed 18446744073709551617"):
            vector.reset(seed=2**64 - 1)
        self.assertEqual(list(vector.episode_steps), [1, 1, 1], "no environment was reset")
        vector.close()

    def test_a_step_before_reset_or_after_the_end_is_an_error(self):
        env = make(2, max_steps=2)
        with self.assertRaisesRegex(RuntimeError, "reset"):
            env.step({})
        env.reset(seed=1)
        for _ in range(2):
            env.step({a: np.zeros(2) for a in env.agents})
        self.assertEqual(env.agents, [])
        with self.assertRaisesRegex(RuntimeError, "call reset"):
            env.step({})
        env.close()
        with self.assertRaisesRegex(RuntimeError, "closed"):
            env.reset()


class ScriptsTest(unittest.TestCase):
    def test_actions_win_over_the_robots_lua_scripts_or_the_scripts_are_dropped(self):
        def episode(path, **kw):
            env = senv.ParallelEnv(path, set={"robots": 6}, **kw)
            out = [env.reset(seed=3)[0]]
            for _ in range(5):
                out.append(env.step({a: np.array([0.05, -0.02]) for a in env.agents})[0])
            env.close()
            return b"".join(o[a].tobytes() for o in out for a in sorted(o))
        # diffusion_numpy.yaml drops the foot-bot's Lua script (its python_controller,
        # which the environment replaces). worlds/diffusion.yaml keeps it: the script sets
        # the wheels every step, and the actions, applied after it, win.
        dropped = episode(DIFFUSION)
        self.assertEqual(dropped, episode(world("diffusion.yaml")))
        if senv.has_keep_scripts():
            self.assertEqual(dropped, episode(world("diffusion.yaml"), keep_scripts=False))
        else:
            with self.assertRaisesRegex(ValueError, "keep_scripts.*python_controller"):
                episode(world("diffusion.yaml"), keep_scripts=False)


class ResetOptionsTest(unittest.TestCase):
    def test_reset_places_the_robots_at_the_poses_given(self):
        env = make(3, observations=["pose"], set={"density": 0.2})
        poses = np.array([[0.8, 0.8, 0.0], [-0.8, 0.8, math.pi / 2], [0.0, -0.8, math.pi]])
        if not hasattr(swarmsim.World, "set_poses"):
            with self.assertRaisesRegex(ValueError, "set_poses"):
                env.reset(seed=1, options={"poses": poses})
            return
        obs, _ = env.reset(seed=1, options={"poses": poses})
        for i, a in enumerate(env.possible_agents):
            x, y, c, s = obs[a]
            self.assertAlmostEqual(x, poses[i, 0], places=3)
            self.assertAlmostEqual(y, poses[i, 1], places=3)
            self.assertAlmostEqual(c, math.cos(poses[i, 2]), places=3)
            self.assertAlmostEqual(s, math.sin(poses[i, 2]), places=3)
        with self.assertRaisesRegex(ValueError, "one row per agent"):
            env.reset(seed=1, options={"poses": poses[:2]})
        with self.assertRaisesRegex(ValueError, "unknown options"):
            env.reset(seed=1, options={"pose": poses})
        env.close()

    def test_a_refused_reset_leaves_the_episode_as_it_was(self):
        env = make(3, observations=["pose"], set={"density": 0.2})
        env.reset(seed=1)
        for _ in range(4):
            obs, *_ = env.step({a: np.full(2, 0.05) for a in env.agents})
        world = env._core.slots[0].world
        hash_before, steps_before = world.state_hash(), world.steps
        bad = np.zeros((3, 3))
        bad[1, 0] = np.nan
        with self.assertRaisesRegex(ValueError, r"row 1 \('footbot#1'\) is not finite"):
            env.reset(seed=2, options={"poses": bad})
        bad[1, 0] = 2e6
        with self.assertRaisesRegex(ValueError, r"row 1 \('footbot#1'\) is beyond \+-1e6 m"):
            env.reset(seed=2, options={"poses": bad})
        with self.assertRaisesRegex(TypeError, "must be numbers"):
            env.reset(seed=2, options={"poses": np.full((3, 3), "x")})
        # The world was not reset: the episode goes on from where it was.
        self.assertEqual((world.state_hash(), world.steps), (hash_before, steps_before))
        after, *_ = env.step({a: np.full(2, 0.05) for a in env.agents})
        self.assertEqual(world.steps, steps_before + 1)
        self.assertFalse(np.array_equal(after["footbot#0"], obs["footbot#0"]))  # driving on
        env.close()
        venv = senv.VectorEnv(DIFFUSION, 2, set={"robots": 3, "density": 0.2})
        venv.reset(seed=1)
        hashes = [s.world.state_hash() for s in venv._core.slots]
        bad = np.zeros((2, 3, 3))
        bad[1, 2, 1] = np.inf  # the second environment's: the first is not reset either
        with self.assertRaisesRegex(ValueError, "row 2 \\('footbot#2'\\) is not finite"):
            venv.reset(seed=5, options={"poses": bad})
        self.assertEqual([s.world.state_hash() for s in venv._core.slots], hashes)
        venv.close()


class EpisodeTest(unittest.TestCase):
    def test_truncation_at_max_steps(self):
        env = make(4, max_steps=5)
        env.reset(seed=1)
        for step in range(1, 6):
            _, _, terminations, truncations, _ = env.step({a: np.zeros(2) for a in env.agents})
            self.assertEqual(set(truncations.values()), {step == 5})
            self.assertEqual(set(terminations.values()), {False})
        self.assertEqual(env.agents, [])
        obs, _ = env.reset(seed=1)
        self.assertEqual(len(obs), 4)
        env.close()

    def test_the_default_episode_is_the_worlds_duration(self):
        env = make(2)
        self.assertEqual(env.max_steps, 600)  # diffusion_numpy.yaml: 60 s of 0.1 s steps
        env.close()
        self.assertIsNone(make(2, max_steps=None).max_steps)

    def test_terminated_agents_leave_and_stand_still(self):
        # An agent leaves when it has driven 2 cm from where it started.
        start = {}

        def terminate(world, agents):
            if agents.step == 1:
                start["xy"] = agents.previous_poses[:, :2].copy()
            return np.hypot(*(agents.poses[:, :2] - start["xy"]).T) > 0.02

        env = make(6, terminate=terminate, max_steps=None, set={"density": 0.2})
        env.reset(seed=3)
        gone = None
        speeds = [0, 0, 0.01, 0.01, 0.01, 0.1]
        for _ in range(30):
            actions = {a: np.full(2, speeds[int(a.split("#")[1])]) for a in env.agents}
            _, _, terminations, _, _ = env.step(actions)
            done = [a for a, t in terminations.items() if t]
            if done and gone is None:
                gone = done[0]
                self.assertNotIn(gone, env.agents)
                at = env.world.poses("footbot")[int(gone.split("#")[1])].copy()
                break
        self.assertEqual(gone, "footbot#5")  # the fast one leaves first
        with self.assertRaisesRegex(ValueError, "'footbot#5' is done"):
            env.step({**{a: np.zeros(2) for a in env.agents}, "footbot#5": np.zeros(2)})
        obs, *_ = env.step({a: np.zeros(2) for a in env.agents})
        self.assertNotIn(gone, obs)
        for _ in range(3):
            env.step({a: np.full(2, 0.1) for a in env.agents})
        # Its wheels got target 0: it rolls to a stop within a few millimetres.
        after = env.world.poses("footbot")[5]
        self.assertLess(math.hypot(*(after[:2] - at[:2])), 0.01)
        env.close()


class LeavingRobotsTest(unittest.TestCase):
    def test_robots_removed_by_their_scripts_terminate_and_copies_are_not_agents(self):
        # worlds/respawn.yaml: robots fail at random and remove themselves; the main script
        # copies live ones (footbot#100, ...). failure_rate 1/s: most fail within 3 s.
        env = senv.ParallelEnv(world("respawn.yaml"), set={"robots": 8, "failure_rate": 1.0},
                               observations=["proximity", "pose"], max_steps=None)
        env.reset(seed=4)
        left = set()
        for _ in range(30):
            live = list(env.agents)
            if not live:
                break
            obs, _, terminations, _, _ = env.step({a: np.full(2, 0.02) for a in live})
            names = env.world.robots["names"]
            for a in live:
                # An agent terminates exactly when its robot is gone.
                self.assertEqual(terminations[a], a not in names, a)
            left |= {a for a in live if terminations[a]}
            # The live agents' observations are their own robots' (robots' rows moved).
            poses = env.world.poses("footbot")
            prox = env.world.proximity("footbot")
            for a in env.agents:
                row = names.index(a)
                np.testing.assert_array_equal(obs[a][24:26], poses[row, :2])
                np.testing.assert_array_equal(obs[a][:24], np.clip(1 - prox[row] / 0.1, 0, 1))
        self.assertGreater(len(left), 0)
        self.assertTrue(any(n.startswith("footbot#1") and len(n) > 9
                            for n in env.world.robots["names"]))  # copies appeared
        self.assertTrue(set(env.agents) <= set(env.possible_agents))
        env.close()


    def test_a_vector_agent_gone_in_the_resets_first_step_is_terminated(self):
        # Half the robots fail in the warm-up step (failure_rate 5/s, 0.1 s steps): those
        # agents never act. Their termination stayed False for the whole episode.
        venv = senv.VectorEnv(world("respawn.yaml"), 2, max_steps=None,
                              set={"robots": 8, "failure_rate": 5.0},
                              observations=["proximity"])
        _, infos = venv.reset(seed=3)
        gone = ~infos["active"]
        self.assertTrue(gone.any() and not gone.all(axis=1).any(), gone)
        going = np.ones(2, dtype=bool)  # environments whose first episode goes on
        for _ in range(3):
            _, rewards, terminations, truncations, infos = venv.step(np.zeros((2, 8, 2)))
            for k in np.flatnonzero(going):
                self.assertTrue(terminations[k][gone[k]].all(), (k, terminations))
                self.assertFalse(truncations[k][gone[k]].any())
                self.assertEqual(set(rewards[k][gone[k]]), {0.0})
                self.assertFalse(infos["active"][k][gone[k]].any())
            going &= infos["active"].any(axis=1)  # an ended one resets at the next step
        self.assertTrue(going.any())
        venv.close()


class RewardTest(unittest.TestCase):
    def test_a_reward_function_sees_the_agents_arrays(self):
        seen = []

        def reward(world, agents):
            seen.append(agents)
            self.assertEqual(agents.observations.shape, (4, 24))
            self.assertEqual(agents.actions.shape, (4, 2))
            self.assertEqual(agents.poses.shape, (4, 3))
            np.testing.assert_array_equal(agents.poses, world.poses("footbot"))
            return agents.actions[:, 0] * 10  # the left wheel's speed, scaled
        env = make(4, reward=reward)
        env.reset(seed=1)
        actions = {a: np.array([0.01 * i, 0.0]) for i, a in enumerate(env.agents)}
        _, rewards, *_ = env.step(actions)
        self.assertEqual(seen[-1].step, 1)
        for i, a in enumerate(env.possible_agents):
            self.assertAlmostEqual(rewards[a], 0.1 * i)
        env.close()

    def test_a_misspelt_swarm_metric_reward_is_refused_at_construction(self):
        # Not at the first step, after the world had moved (British spelling).
        self.assertIn("mean_nearest_neighbor_distance", make(2).world.metric_names)
        with self.assertRaisesRegex(ValueError, r"^reward: the world declares no metric "
                                                r"'mean_nearest_neighbour_distance'; did you mean "
                                                r"'mean_nearest_neighbor_distance'\?"):
            make(2, reward="mean_nearest_neighbour_distance")
        # A robot-level one: the robots record it, and until they do it is 0
        # (it was a KeyError at every step before the first sim.recordMetric).
        # A name no robot ever records (misspelt) is said once, after 100 steps of 0.
        env = make(2, reward="my_own_robot_metric", max_steps=None)
        env.reset(seed=1)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for _ in range(99):
                _, rewards, *_ = env.step({a: np.zeros(2) for a in env.agents})
                self.assertEqual(set(rewards.values()), {0.0})
            self.assertEqual(caught, [])
            for _ in range(5):
                env.step({a: np.zeros(2) for a in env.agents})
        self.assertEqual(len(caught), 1)
        self.assertIn("no robot has recorded metric 'my_own_robot_metric' in 100 steps",
                      str(caught[0].message))
        env.close()

    def test_a_swarm_metric_as_the_reward(self):
        env = make(6, reward="mean_nearest_neighbor_distance")
        env.reset(seed=1)
        for step in range(1, 12):
            _, rewards, *_ = env.step({a: np.zeros(2) for a in env.agents})
            metric = env.world.metrics.get("mean_nearest_neighbor_distance")
            if metric is None:
                self.assertEqual(set(rewards.values()), {0.0})  # no value yet
            else:
                self.assertEqual(set(rewards.values()), {metric})
        self.assertIsNotNone(metric)  # recorded every 10 steps
        env.close()

    def test_bad_reward_and_termination_results_are_errors(self):
        env = make(3, reward=lambda w, a: np.zeros(5))
        env.reset(seed=1)
        with self.assertRaisesRegex(ValueError, r"reward.*\(3,\).*shape \(5,\)"):
            env.step({a: np.zeros(2) for a in env.agents})
        env.close()
        # None read as NaN ("not finite"), text as numpy's bare "could not convert".
        for returned, pattern in [(None, "reward: the function returned None"),
                                  ("x", "reward: the function must return numbers.*got str")]:
            env = make(3, reward=lambda w, a, r=returned: r)
            env.reset(seed=1)
            with self.assertRaisesRegex(TypeError, pattern):
                env.step({a: np.zeros(2) for a in env.agents})
            env.close()
        env = make(3, terminate=lambda w, a: np.zeros(3))
        env.reset(seed=1)
        with self.assertRaisesRegex(ValueError, "terminate.*booleans"):
            env.step({a: np.zeros(2) for a in env.agents})
        env.close()


    def test_world_options_the_environment_sets_itself_are_refused_by_name(self):
        # seed= gave pybind11's "got multiple values for keyword argument 'seed'"; a
        # controller of the agents' own model was dropped without a word.
        for key, instead in (("seed", "reset"), ("threads", "threads="), ("set", "set=")):
            with self.assertRaisesRegex(ValueError, rf"^world_options: '{key}' is the "
                                                    rf"environment's own: use {instead}"):
                make(2, world_options={key: 1})
        with self.assertRaisesRegex(ValueError, r"world_options: controllers of 'footbot', the "
                                                r"agents' model"):
            make(2, world_options={"controllers": {"footbot": lambda *a: None}}).reset(seed=1)

    def test_the_environment_is_not_called_again_from_its_own_reward(self):
        # env.reset() in the reward lost the episode's truncation; env.step() in it
        # stepped the world twice; world.step() in it desynchronised the step count.
        holder = {}
        calls = {
            "reset": lambda: holder["env"].reset(seed=5),
            "step": lambda: holder["env"].step({}),
            "close": lambda: holder["env"].close(),
        }
        for name, call in calls.items():
            env = make(3, reward=lambda w, a, call=call: (call(), 0.0)[1], max_steps=3)
            holder["env"] = env
            env.reset(seed=1)
            with self.assertRaisesRegex(RuntimeError, rf"ParallelEnv.{name}\(\): called from "
                                                      rf"inside the environment's own reward"):
                env.step({a: np.zeros(2) for a in env.agents})
            env.close()
        env = make(3, terminate=lambda w, a: (w.step(1), False)[1], max_steps=3)
        env.reset(seed=1)
        with self.assertRaisesRegex(RuntimeError, r"the reward or terminate function stepped the "
                                                  r"world \(\d+ -> \d+ steps\)"):
            env.step({a: np.zeros(2) for a in env.agents})
        env.close()


class DeclarationTest(unittest.TestCase):
    def test_bad_declarations_are_clear_errors(self):
        with self.assertRaisesRegex(TypeError, "the world must be a path .* not NoneType"):
            senv.ParallelEnv(None)
        # bool() took "no" as True.
        with self.assertRaisesRegex(TypeError, "clip_actions must be True or False, got 'no'"):
            make(2, clip_actions="no")
        with self.assertRaisesRegex(TypeError, "keep_scripts must be True or False, got 0"):
            make(2, keep_scripts=0)
        env = senv.ParallelEnv(os.fsencode(DIFFUSION), set={"robots": 2})  # bytes: a path too
        env.close()
        with self.assertRaisesRegex(ValueError, "no block 'sonar'.*proximity"):
            make(2, observations=["sonar"])
        with self.assertRaisesRegex(ValueError, r"no joint \['wheel'\].*leftMotor"):
            make(2, actions=senv.JointTargets(["wheel"]))
        with self.assertRaisesRegex(
                ValueError, r"model='kilobot': the world has no model 'kilobot' \(it has footbot\)"):
            make(2, model="kilobot")
        with self.assertRaisesRegex(ValueError, "max_steps"):
            make(2, max_steps=0)
        with self.assertRaisesRegex(ValueError, "does not exist|no such|cannot|not found"):
            senv.ParallelEnv(world("nope.yaml"))
        # Seeds and counts are integers, said by name (int("x") said nothing of a seed).
        with self.assertRaisesRegex(TypeError, r"^seed must be an integer >= 0, got 1.5"):
            make(2, seed=1.5)
        with self.assertRaisesRegex(TypeError, r"^num_envs must be an integer >= 1, got 2.5"):
            senv.VectorEnv(DIFFUSION, 2.5, set={"robots": 2})
        with self.assertRaisesRegex(TypeError, r"^num_envs must be an integer >= 1, got True"):
            senv.VectorEnv(DIFFUSION, True, set={"robots": 2})
        # A huge count is refused at once (it filled memory building its slots).
        for huge in (10**9, 10**20):
            with self.assertRaisesRegex(ValueError, r"^num_envs must be at most 65,536"):
                senv.VectorEnv(DIFFUSION, huge, set={"robots": 2})
        env = make(2)
        with self.assertRaisesRegex(TypeError, r"^reset: seed must be an integer >= 0, got 'x'"):
            env.reset(seed="x")
        with self.assertRaisesRegex(ValueError, r"^reset: seed must be an integer >= 0, got -1"):
            env.reset(seed=-1)
        env.reset(seed=np.int64(3))  # numpy integers are integers
        env.close()
        venv = senv.VectorEnv(DIFFUSION, 2, set={"robots": 2})
        with self.assertRaisesRegex(TypeError, r"^reset: seed\[1\] must be an integer"):
            venv.reset(seed=[1, 2.0])
        venv.close()

    def test_declarations_found_wrong_by_qa_are_refused_at_construction(self):
        # A scale that is not finite made every step fail, blaming the controller.
        for scale in (float("nan"), float("inf"), 1e308):
            with self.assertRaisesRegex(ValueError, r"^actions: scale must be finite"):
                make(2, actions=senv.JointTargets(scale=scale, high=10.0))
        # 10**9 neighbours allocated 22 GiB per read.
        with self.assertRaisesRegex(ValueError, r"neighbours=\.\.\.\) must be 1 to 10000"):
            senv.range_and_bearing(neighbours=10**9)
        self.assertEqual(senv.range_and_bearing(4.0).name, "range_and_bearing")
        with self.assertRaisesRegex(ValueError, r"joint \['leftMotor'\] listed twice"):
            make(2, actions=senv.JointTargets(["leftMotor", "leftMotor"]))
        with self.assertRaisesRegex(ValueError, r"observation 'ground': model 'footbot' gives it "
                                                r"no columns"):
            make(2, observations=["proximity", "ground"])
        with self.assertRaisesRegex(TypeError, r"^max_steps .* must be an integer >= 1, got True"):
            make(2, max_steps=True)
        with self.assertRaisesRegex(TypeError, r"^max_steps .*got 'x'"):
            make(2, max_steps="x")
        self.assertEqual(make(2, max_steps=20.0).max_steps, 20)
        with self.assertRaisesRegex(ValueError, r"^step_threads is 0 \(every core\) or 1 to 256"):
            senv.VectorEnv(DIFFUSION, 2, set={"robots": 2}, step_threads=999)
        env = make(2)
        with self.assertRaisesRegex(TypeError, r"^reset: options must be a dict"):
            env.reset(options=[1])
        env.close()
        # A closed environment says so, rather than handing out None or zeros.
        for read in (lambda: env.world, env.state):
            with self.assertRaisesRegex(RuntimeError, "the environment is closed"):
                read()

    def test_a_block_whose_width_changes_is_an_error_not_a_broadcast(self):
        calls = [0]

        def shrinking(world, model):
            calls[0] += 1
            return np.full((len(world.poses(model)), 2 if calls[0] == 1 else 1), 1.0)
        env = make(3, observations=[senv.Observation("mine", shrinking)])
        with self.assertRaisesRegex(ValueError, r"observation 'mine': read\(\) returned shape "
                                                r"\(3, 1\), expected \(3, 2\)"):
            env.reset(seed=1)
        env.close()

    def test_pose_block_is_the_worlds_pose(self):
        env = make(5, observations=["pose"])
        obs, _ = env.reset(seed=2)
        poses = env.world.poses("footbot")
        for i, a in enumerate(env.possible_agents):
            x, y, c, s = obs[a]
            self.assertEqual((x, y), (poses[i, 0], poses[i, 1]))
            self.assertAlmostEqual(c, math.cos(poses[i, 2]), places=9)
            self.assertAlmostEqual(s, math.sin(poses[i, 2]), places=9)
        env.close()

    def test_a_custom_observation_block(self):
        def clock(world, model):
            return np.full((len(world.poses(model)), 1), world.time)
        env = make(3, observations=["proximity", senv.Observation("clock", clock, 0.0, 1e6)])
        obs, _ = env.reset(seed=1)
        self.assertEqual(obs["footbot#0"][-1], 0.1)  # after the reset's step
        obs, *_ = env.step({a: np.zeros(2) for a in env.agents})
        self.assertAlmostEqual(obs["footbot#0"][-1], 0.2)
        self.assertEqual(env.observation_space("footbot#0").shape, (25,))
        env.close()

    def test_a_block_that_reads_nan_is_an_error_naming_it_and_the_agent(self):
        def late_nan(world, model):
            values = np.zeros((len(world.poses(model)), 2))
            if world.steps >= 3:
                values[2, 1] = np.nan  # the third robot's second column
            return values
        env = make(3, observations=["proximity", senv.Observation("broken", late_nan)])
        env.reset(seed=1)
        env.step({a: np.zeros(2) for a in env.agents})  # steps 2: still numbers
        with self.assertRaises(ValueError) as e:
            env.step({a: np.zeros(2) for a in env.agents})
        self.assertIn("observation 'broken': column 1 is NaN for agent 'footbot#2'",
                      str(e.exception))
        env.close()
        # inf is a reading, not an error: rays that see nothing.
        env = make(3, observations=[senv.proximity_distance()])
        obs, _ = env.reset(seed=1)
        self.assertTrue(np.isinf(obs["footbot#0"]).any())
        env.close()

    def test_range_and_bearing_ground_and_light_blocks(self):
        env = make(6, set={"footbot.with_rab": True, "footbot.with_ground": True,
                           "footbot.with_light": True},
                   observations=[senv.range_and_bearing(neighbours=3), "ground", "light"])
        self.assertEqual(env.observation_space("footbot#0").shape, (9 + 12 + 24,))
        obs, _ = env.reset(seed=1)
        rab = env.world.range_and_bearing("footbot")
        heard = np.diff(rab["offsets"])
        for i, a in enumerate(env.possible_agents):
            block = obs[a][:9].reshape(3, 3)
            n = min(3, heard[i])
            np.testing.assert_array_equal(block[:n, 0], 1.0)
            np.testing.assert_array_equal(block[n:], 0.0)
            at = rab["offsets"][i]
            np.testing.assert_array_equal(block[:n, 1], rab["range"][at:at + n])
            np.testing.assert_array_equal(block[:n, 2], rab["bearing"][at:at + n])
            self.assertTrue(env.observation_space(a).contains(obs[a]))
        self.assertTrue(heard.max() > 0)  # 6 robots, 3 m boards: they hear each other
        env.close()


class VectorEnvTest(unittest.TestCase):
    def make(self, envs=3, robots=5, **kw):
        kw.setdefault("set", {})
        kw["set"] = {"robots": robots, **kw["set"]}
        return senv.VectorEnv(DIFFUSION, envs, **kw)

    def test_shapes_spaces_and_metadata(self):
        venv = self.make(3, 5)
        self.assertEqual(venv.num_envs, 3)
        self.assertEqual(venv.single_observation_space.shape, (5, 24))
        self.assertEqual(venv.observation_space.shape, (3, 5, 24))
        self.assertEqual(venv.single_action_space.shape, (5, 2))
        self.assertEqual(venv.action_space.shape, (3, 5, 2))
        self.assertIn(str(venv.metadata["autoreset_mode"]).split(".")[-1],
                      ("NextStep", "NEXT_STEP"))
        obs, infos = venv.reset(seed=1)
        self.assertEqual(obs.shape, (3, 5, 24))
        self.assertTrue(venv.observation_space.contains(obs))
        obs, rewards, terminations, truncations, infos = venv.step(venv.action_space.sample())
        self.assertTrue(venv.observation_space.contains(obs))
        self.assertEqual(rewards.shape, (3, 5))
        self.assertEqual(terminations.shape, (3, 5))
        self.assertEqual(terminations.dtype, bool)
        self.assertEqual(truncations.shape, (3, 5))
        self.assertEqual(infos["active"].shape, (3, 5))
        venv.close()

    def test_each_environment_is_the_parallel_env_with_its_seed(self):
        venv = self.make(3, 5)
        obs, _ = venv.reset(seed=20)  # environment k: seed 20 + k
        rng = np.random.default_rng(5)
        actions = [rng.uniform(-0.1, 0.1, size=(3, 5, 2)) for _ in range(4)]
        frames = [obs]
        for a in actions:
            frames.append(venv.step(a)[0])
        for k in range(3):
            env = make(5)
            o, _ = env.reset(seed=20 + k)
            mine = [np.stack([o[a] for a in env.possible_agents])]
            for a in actions:
                o, *_ = env.step({name: a[k, i] for i, name in enumerate(env.possible_agents)})
                mine.append(np.stack([o[n] for n in env.possible_agents]))
            for x, y in zip(frames, mine):
                self.assertEqual(x[k].tobytes(), y.tobytes())
            env.close()
        venv.close()

    def test_same_seed_same_arrays_at_any_thread_count(self):
        # threads: each world's; parallel: the worlds stepped by swarmsim.step_worlds (where
        # the module has it) on 2 workers, or one after the other.
        def run(threads, parallel=True):
            venv = self.make(3, 6, threads=threads, step_threads=2)
            venv._core.parallel = parallel
            out = [venv.reset(seed=7)[0]]
            rng = np.random.default_rng(3)
            for _ in range(5):
                obs, rewards, *_ = venv.step(rng.uniform(-0.1, 0.1, size=(3, 6, 2)))
                out += [obs, rewards]
            venv.close()
            return b"".join(x.tobytes() for x in out)
        first = run(1)
        self.assertEqual(first, run(2))
        self.assertEqual(first, run(1, parallel=False))

    def test_next_step_autoreset(self):
        venv = self.make(2, 4, max_steps=3)
        venv.reset(seed=1)
        zeros = np.zeros((2, 4, 2))
        for step in range(1, 4):
            obs, rewards, terminations, truncations, _ = venv.step(zeros + 0.05)
            np.testing.assert_array_equal(truncations, step == 3)
            self.assertFalse(terminations.any())
        last = obs
        seeds_before = venv.seeds
        # The next step resets both: its actions are ignored (even ones out of bounds).
        obs, rewards, terminations, truncations, infos = venv.step(zeros + np.nan)
        self.assertNotEqual(venv.seeds, seeds_before)
        np.testing.assert_array_equal(rewards, 0.0)
        self.assertFalse(terminations.any() or truncations.any())
        self.assertTrue(infos["active"].all())
        np.testing.assert_array_equal(venv.episode_steps, [0, 0])
        self.assertNotEqual(obs.tobytes(), last.tobytes())
        # ... and its observations are the new episodes' first ones.
        for k in range(2):
            env = make(4)
            o, _ = env.reset(seed=venv.seeds[k])
            np.testing.assert_array_equal(obs[k], np.stack([o[a] for a in env.possible_agents]))
            env.close()
        obs, rewards, *_ = venv.step(zeros + 0.05)
        np.testing.assert_array_equal(venv.episode_steps, [1, 1])
        self.assertTrue((rewards > 0).all())
        venv.close()

    def test_terminated_agents_stay_done_until_their_environment_resets(self):
        # In environment 0 agent 0 leaves at step 2; environment 1 ends at step 2.
        def terminate(world, agents):
            out = np.zeros(len(agents.names), dtype=bool)
            if agents.step >= 2:
                out[0] = True
                if agents.env == 1:
                    out[:] = True
            return out
        venv = self.make(2, 3, terminate=terminate, max_steps=None)
        venv.reset(seed=1)
        act = np.full((2, 3, 2), 0.05)
        venv.step(act)
        obs, rewards, terminations, truncations, infos = venv.step(act)
        np.testing.assert_array_equal(terminations, [[True, False, False], [True, True, True]])
        np.testing.assert_array_equal(infos["active"], [[False, True, True], [False] * 3])
        act[0, 0] = 7.0  # an inactive agent's action is ignored
        obs, rewards, terminations, truncations, infos = venv.step(act)
        np.testing.assert_array_equal(terminations[0], [True, False, False])
        self.assertEqual(rewards[0, 0], 0.0)
        self.assertTrue((rewards[0, 1:] > 0).all())
        np.testing.assert_array_equal(venv.episode_steps, [3, 0])  # environment 1 was reset
        venv.close()

    def test_actions_outside_the_space_name_the_environment_and_agent(self):
        venv = self.make(2, 3)
        venv.reset(seed=1)
        act = np.zeros((2, 3, 2))
        act[1, 2, 0] = 0.3
        with self.assertRaisesRegex(ValueError, r"environment 1, agent 'footbot#2'.*outside"):
            venv.step(act)
        with self.assertRaisesRegex(ValueError, r"shape \(3, 2\).*\(2, 3, 2\)"):
            venv.step(np.zeros((3, 2)))
        venv.close()

    def test_reset_mask_resets_only_some_environments(self):
        venv = self.make(2, 3)
        venv.reset(seed=1)
        for _ in range(3):
            venv.step(np.full((2, 3, 2), 0.05))
        hash1 = venv.worlds[1].state_hash()
        obs, _ = venv.reset(seed=[30, 31], options={"reset_mask": np.array([True, False])})
        self.assertEqual(venv.seeds[0], 30)
        np.testing.assert_array_equal(venv.episode_steps, [0, 3])
        self.assertEqual(venv.worlds[1].state_hash(), hash1)
        venv.close()


# Stand-ins for the names Gymnasium 1.x and PettingZoo document (gymnasium.spaces.Box,
# gymnasium.vector.VectorEnv and AutoresetMode, pettingzoo.ParallelEnv), to check that
# swarmsim.spaces and swarmsim.env take them when the libraries are importable.
STUBS = {
    "gymnasium/__init__.py": "from . import spaces, vector\n",
    "gymnasium/spaces.py": (
        "import numpy as np\n"
        "class Box:\n"
        "    def __init__(self, low, high, shape=None, dtype=np.float32, seed=None):\n"
        "        self.dtype = np.dtype(dtype)\n        self.shape = tuple(shape)\n"
        "        self.low = np.broadcast_to(low, shape).astype(dtype)\n"
        "        self.high = np.broadcast_to(high, shape).astype(dtype)\n"
        "    def contains(self, x):\n"
        "        return bool(x.shape == self.shape and np.all(x >= self.low)\n"
        "                    and np.all(x <= self.high))\n"),
    "gymnasium/vector.py": (
        "import enum\n"
        "class AutoresetMode(enum.Enum):\n"
        "    NEXT_STEP = 'NextStep'\n    SAME_STEP = 'SameStep'\n    DISABLED = 'Disabled'\n"
        "class VectorEnv:\n"
        "    metadata = {}\n    closed = False\n"
        "    def close(self, **kwargs):\n        self.closed = True\n"
        "    def __del__(self):\n"
        "        if not getattr(self, 'closed', True):\n            self.close()\n"),
    "pettingzoo/__init__.py": (
        "class ParallelEnv:\n"
        "    def observation_space(self, agent):\n        raise NotImplementedError\n"
        "    @property\n    def num_agents(self):\n        return len(self.agents)\n"
        "    @property\n    def unwrapped(self):\n        return self\n"),
}

CHECK_WITH_STUBS = """
import numpy as np, gymnasium, pettingzoo
from swarmsim import env, spaces
assert spaces.GYMNASIUM and spaces.Box is gymnasium.spaces.Box
assert issubclass(env.VectorEnv, gymnasium.vector.VectorEnv)
assert issubclass(env.ParallelEnv, pettingzoo.ParallelEnv)
assert env.VectorEnv.metadata["autoreset_mode"] is gymnasium.vector.AutoresetMode.NEXT_STEP
p = env.ParallelEnv(PATH, set={"robots": 3})
obs, _ = p.reset(seed=1)
assert type(p.observation_space("footbot#0")) is gymnasium.spaces.Box
assert p.unwrapped is p and p.num_agents == 3
p.step({a: np.zeros(2) for a in p.agents})
v = env.VectorEnv(PATH, 2, set={"robots": 3})
obs, _ = v.reset(seed=1)
assert type(v.single_observation_space) is gymnasium.spaces.Box
assert v.observation_space.contains(v.step(np.zeros((2, 3, 2)))[0])
v.close()
assert v.closed
print("ok")
"""


class ThreadsTest(unittest.TestCase):
    def test_a_second_thread_inside_an_environment_is_refused_and_nothing_is_lost(self):
        # Two threads stepping one VectorEnv lost steps and desynchronised its episodes.
        import threading
        armed, inside, release = threading.Event(), threading.Event(), threading.Event()

        def slow(world, model):
            if armed.is_set():
                inside.set()
                release.wait(30)
            return np.zeros((len(world.poses(model)), 1))
        venv = senv.VectorEnv(DIFFUSION, 2, set={"robots": 3}, max_steps=50,
                              observations=["proximity", senv.Observation("slow", slow)])
        venv.reset(seed=1)
        actions = np.zeros((2, 3, 2))
        armed.set()
        worker = threading.Thread(target=venv.step, args=(actions,))
        worker.start()
        self.assertTrue(inside.wait(30))
        armed.clear()
        for call in (lambda: venv.step(actions), lambda: venv.reset(seed=2), venv.close):
            with self.assertRaisesRegex(RuntimeError, "another thread is inside a call of this "
                                                      "environment"):
                call()
        release.set()
        worker.join()
        venv.step(actions)  # the first thread's call is over: this one may go in
        self.assertEqual(list(venv.episode_steps), [2, 2])
        self.assertEqual([w.steps for w in venv.worlds], [3, 3])
        venv.close()


class WrapperAttributesTest(unittest.TestCase):
    def test_unwrapped_spec_and_np_random_are_there_without_the_libraries(self):
        # Wrappers and training code read them (AttributeError without Gymnasium/PettingZoo).
        p = make(2)
        self.assertIs(p.unwrapped, p)
        p.close()
        v = senv.VectorEnv(DIFFUSION, 2, set={"robots": 2})
        self.assertIs(v.unwrapped, v)
        self.assertIsNone(v.spec)
        self.assertIsInstance(v.np_random, np.random.Generator)
        self.assertEqual(v.get_wrapper_attr("num_envs"), 2)
        v.reset(seed=11)  # seeds np_random as Gymnasium's VectorEnv.reset does
        self.assertEqual(v.np_random_seed, 11)
        first = v.np_random.random(4)
        v.reset(seed=11)
        np.testing.assert_array_equal(v.np_random.random(4), first)
        v.reset(seed=12)
        self.assertFalse(np.array_equal(v.np_random.random(4), first))
        v.close()


class LibrariesTest(unittest.TestCase):
    def test_gymnasium_and_pettingzoo_types_are_used_when_importable(self):
        import os
        import subprocess
        import sys
        import tempfile
        with tempfile.TemporaryDirectory() as folder:
            for name, text in STUBS.items():
                os.makedirs(os.path.join(folder, os.path.dirname(name)), exist_ok=True)
                with open(os.path.join(folder, name), "w") as f:
                    f.write(text)
            path = folder + os.pathsep + os.environ.get("PYTHONPATH", "")
            script = f"PATH = {DIFFUSION!r}\n" + CHECK_WITH_STUBS
            p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                               env={**os.environ, "PYTHONPATH": path}, timeout=300)
            self.assertEqual(p.returncode, 0, p.stderr)
            self.assertEqual(p.stdout.strip(), "ok")


class SpacesTest(unittest.TestCase):
    def test_the_fallback_box_is_used_without_gymnasium(self):
        if importlib.util.find_spec("gymnasium") is None:
            self.assertIs(spaces.Box, spaces.FallbackBox)
            self.assertFalse(spaces.GYMNASIUM)
        else:
            import gymnasium
            self.assertIs(spaces.Box, gymnasium.spaces.Box)

    def test_box_contains_sample_and_seed(self):
        box = spaces.FallbackBox(np.array([0.0, -np.inf, -1.0]), np.array([1.0, np.inf, np.inf]),
                                 dtype=np.float64)
        self.assertEqual(box.shape, (3,))
        self.assertTrue(box.contains(np.array([0.5, -1e9, 3.0])))
        self.assertFalse(box.contains(np.array([1.5, 0.0, 0.0])))  # above high
        self.assertFalse(box.contains(np.array([0.5, 0.0])))  # wrong shape
        self.assertFalse(box.contains(np.array([0.5, np.nan, 0.0])))
        self.assertFalse(box.contains(np.array([0.5, 0.0, 0.0]) + 0j))  # not castable
        box.seed(4)
        a = [box.sample() for _ in range(20)]
        box.seed(4)
        b = [box.sample() for _ in range(20)]
        self.assertEqual(np.stack(a).tobytes(), np.stack(b).tobytes())
        self.assertTrue(all(box.contains(x) for x in a))
        self.assertFalse(box.is_bounded("both"))
        self.assertTrue(spaces.FallbackBox(-1, 1, (2,)).is_bounded())
        self.assertEqual(spaces.FallbackBox(-1, 1, (2,)).sample().dtype, np.float32)
        with self.assertRaisesRegex(ValueError, "low must be <= high"):
            spaces.FallbackBox(1, 0, (2,))


if __name__ == "__main__":
    unittest.main()
