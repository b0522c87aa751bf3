"""The engine under swarmsim.env's ParallelEnv and VectorEnv: K worlds of one world file,
each with the same N agents (the robots of one model), as arrays.

Not public: use swarmsim.env. One World per environment; the agents' actions reach the
model's joints through a Python controller of the World (called in the actuate phase, after
the robots' own scripts, so the actions win over whatever a script set); observations are
read after the step into (K, N, D) buffers and transformed in one numpy call per block for
all K worlds.
"""

import difflib
import os
import re
import warnings
import weakref

import numpy as np

from . import _swarmsim

World = _swarmsim.World
MAX_SEED = 2**31  # seeds drawn for later episodes lie in [0, MAX_SEED)


MAX_NUM_ENVS = 65536  # worlds a VectorEnv holds


def whole_number(value, what, minimum=0):
    """`value` as an int if it is a whole number (int or numpy integer, not a bool) of at
    least `minimum`; else TypeError or ValueError naming `what` (``"seed"``)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{what} must be an integer >= {minimum}, got {value!r} "
                        f"({type(value).__name__})")
    if value < minimum:
        raise ValueError(f"{what} must be an integer >= {minimum}, got {value}")
    return int(value)


def step_worlds(worlds, n=1, threads=0, parallel=True):
    """Steps worlds n times: with swarmsim.step_worlds (the worlds in parallel on `threads`
    workers, 0: every core, the GIL released) when the module has it and parallel is True,
    else one after the other (each on its own threads)."""
    step = getattr(_swarmsim, "step_worlds", None) if parallel else None
    if step is not None and len(worlds) > 1:
        step(list(worlds), n, threads)
    else:
        for w in worlds:
            w.step(n)


def has_parallel_step():
    """True if this build has swarmsim.step_worlds (else environments step in a loop)."""
    return hasattr(_swarmsim, "step_worlds")


def has_keep_scripts():
    """True if this build's World takes keep_scripts= (drops the Lua scripts of the models
    a Python controller drives)."""
    return "keep_scripts" in (World.__init__.__doc__ or "")


def has_reset():
    """True if this build's World has reset(seed) (else a reset loads the file again)."""
    return hasattr(World, "reset")


class AgentArrays:
    """What a reward or termination function receives for one world, agents in
    ``possible_agents`` order (N rows): ``names``; ``active`` (N,) bool, the agents that
    acted in this step; ``present`` (N,) bool, the agents whose robot is in the world;
    ``observations`` (N, D), after the step; ``actions`` (N, A), the actions of this step
    (zeros for inactive agents); ``poses`` and ``previous_poses`` (N, 3: x, y, yaw in
    planar worlds; N x 7 x, y, z, qw, qx, qy, qz otherwise), after and before the step;
    ``step``, the episode's step count (1 after the first step); ``env``, the environment's
    index in a VectorEnv (0 in a ParallelEnv); ``model``, the model's name.
    Rows of agents whose robot is gone hold their last values."""

    __slots__ = ("names", "active", "present", "observations", "actions", "poses",
                 "previous_poses", "step", "env", "model")


class _WorldSlot:
    """One world and where its agents are in the model's rows."""

    def __init__(self, k):
        self.k = k                 # its index among the K worlds
        self.world = None
        self.seed = None           # the seed of the current episode
        self.rng = None            # draws the seeds of later episodes
        self.indices = None        # the model's robots' instance indices, row order
        self.row_of = None         # (N,) int: agent i's row in the model's arrays, -1: gone
        self.identity = False      # rows are the agents, in order
        self.targets = None        # (J, rows) joint targets for the next step
        self.called = False        # the controller ran in the last step
        self.fresh = False         # loaded with `seed`, never stepped


class Core:
    """K worlds x N agents. spec: a dict of the environment's declarations (env.py)."""

    def __init__(self, spec, num_envs):
        self.spec = spec
        # The user's reward or terminate function is running: the environment's own
        # calls are refused from it (env.py, _one_thread_at_a_time).
        self.in_callback = None
        try:  # str() made None 'None' ("world file 'None' not found"), bytes "b'...'"
            self.path = os.fsdecode(spec["world"])
        except TypeError:
            raise TypeError(f"the world must be a path (str, bytes or os.PathLike), not "
                            f"{type(spec['world']).__name__}") from None
        self.model = spec["model"]
        self.K = whole_number(num_envs, "num_envs", 1)
        # Each is a World of its own: a huge count filled memory for ever
        # building the slots before anything said no.
        if self.K > MAX_NUM_ENVS:
            raise ValueError(f"num_envs must be at most {MAX_NUM_ENVS:,} (each is a world of its "
                             f"own), got {self.K:,}")
        self.slots = [_WorldSlot(k) for k in range(self.K)]
        self.parallel = True  # step the worlds with swarmsim.step_worlds where it exists
        self.reset_failures = 0  # World.reset calls that failed (the world was loaded again)
        if self.model is None:
            self.model = self._find_model(spec["seed"])
        # The first world tells the agents, joints and sizes.
        try:
            first = self._load(0, spec["seed"])
        except ValueError:
            # A model= the world does not have fails as our controller's model: say model=.
            models = self._models_without_controller(spec["seed"])
            if models is not None and self.model not in models:
                raise ValueError(f"{self.path}: model={self.model!r}: the world has no model "
                                 f"'{self.model}' (it has {', '.join(models) or 'none'})"
                                 ) from None
            raise
        self.slots[0].fresh = True
        self.base_seed = spec["seed"] if spec["seed"] is not None else _file_seed(first)
        self._check_reward_metric(first)
        robots = first.robots
        models = sorted(set(robots["models"]))
        if self.model not in models:
            raise ValueError(f"{self.path}: no model '{self.model}' (models: {models})")
        self.agents = [n for n, m in zip(robots["names"], robots["models"]) if m == self.model]
        if not self.agents:
            raise ValueError(f"{self.path}: model '{self.model}' has no robots")
        self.N = len(self.agents)
        self.agent_index = {name: i for i, name in enumerate(self.agents)}
        self.actions = spec["actions"].bind(list(first.joint_names(self.model)), self.model)
        self.joint_names = list(self.actions.joints)  # the joints the controller sets
        self.A = self.actions.size
        self.planar = first.planar
        self.pose_columns = 3 if self.planar else 7
        self.max_steps = spec["max_steps"]
        if self.max_steps == "world":
            self.max_steps = first.default_steps
        # Observation blocks: a first read gives each one's width.
        self._map(0)
        self.blocks = []
        column = 0
        for item in spec["observations"]:
            raw = np.asarray(item.read(first, self.model, None), dtype=np.float64)
            if raw.ndim != 2 or raw.shape[0] != len(self.slots[0].indices):
                raise ValueError(f"observation '{item.name}': read() must return one row per "
                                 f"robot of '{self.model}', got shape {raw.shape}")
            width = item.transform(raw[None]).shape[-1]
            if width == 0:
                raise ValueError(f"observation '{item.name}': model '{self.model}' gives it no "
                                 f"columns (the model has none of the sensors it reads)")
            self.blocks.append((item, raw.shape[1], column, column + width))
            column += width
        self.D = column
        if self.D == 0:
            raise ValueError("observations: the agents observe nothing (an empty list or "
                             "blocks of width 0)")
        self.obs_low = np.empty(self.D)
        self.obs_high = np.empty(self.D)
        for item, _, a, b in self.blocks:
            self.obs_low[a:b] = item.low_for(b - a)
            self.obs_high[a:b] = item.high_for(b - a)
        # Per world, per agent state.
        K, N = self.K, self.N
        self.raw = [np.zeros((K, N, cols)) for _, cols, _, _ in self.blocks]
        self.obs = np.zeros((K, N, self.D))
        self.poses = np.zeros((K, N, self.pose_columns))
        self.previous_poses = np.zeros_like(self.poses)
        self.last_actions = np.zeros((K, N, self.A))
        self.rewards = np.zeros((K, N))
        self.terminated = np.zeros((K, N), dtype=bool)
        self.truncated = np.zeros((K, N), dtype=bool)
        self.active = np.zeros((K, N), dtype=bool)
        self.present = np.zeros((K, N), dtype=bool)
        self.episode_steps = np.zeros(K, dtype=np.int64)
        self.closed = False

    # --- worlds -----------------------------------------------------------------------

    def _controller(self, slot):
        # Weak references: the World holds this function in C++, where Python's garbage
        # collector cannot see, so a strong one made env -> world -> control -> env a cycle
        # it never freed (an env dropped without close() kept its World, ~5 MB each).
        core_ref, slot_ref = weakref.ref(self), weakref.ref(slot)

        def control(robots):
            self, slot = core_ref(), slot_ref()
            if self is None or slot is None:
                return {}  # the environment is gone; its world goes with it
            slot.called = True
            indices = robots.indices
            if indices != slot.indices:  # robots came or went in this step
                self._remap(slot, indices, robots.names)
                self._write_targets(slot, self.actions.targets(self.last_actions[slot.k]))
            return {name: slot.targets[j] for j, name in enumerate(self.joint_names)}
        return control

    def _check_reward_metric(self, world):
        # A reward named by a metric: a robot-level one is whatever the robots record (known
        # only once they have), but a near miss of a declared swarm-level one is a typo.
        name = getattr(self.spec["reward"], "metric", None)
        declared = list(getattr(world, "metric_names", []))
        if name is None or name in declared:
            return
        near = difflib.get_close_matches(name, declared, n=1)
        if near:
            raise ValueError(f"reward: the world declares no metric '{name}'; did you mean "
                             f"'{near[0]}'? (declared: {', '.join(declared)})")

    def _probe(self, seed):
        """The world loaded without our controller."""
        options = dict(self.spec["world_options"])
        return World(self.path, seed=seed, set=self.spec["set"], threads=self.spec["threads"],
                     **options)

    def _models_without_controller(self, seed):
        """The world's models, or None if it does not load without our controller either."""
        try:
            probe = self._probe(seed)
        except ValueError:
            return None
        models = sorted(set(probe.robots["models"]))
        probe.close()
        return models

    def _find_model(self, seed):
        """The world's only model with joints (a probe load, without our controller)."""
        probe = self._probe(seed)
        robots = probe.robots
        models = sorted(set(robots["models"]))
        driven = [m for m in models if probe.joint_names(m)]
        probe.close()
        if len(driven) != 1:
            raise ValueError(f"{self.path}: pass model=: the world's models with joints are "
                             f"{driven or 'none'} (models: {models})")
        return driven[0]

    def _load(self, k, seed):
        slot = self.slots[k]
        if slot.world is not None:
            slot.world.close()
            slot.world = None
        options = dict(self.spec["world_options"])
        controllers = dict(options.pop("controllers", {}))
        if self.model in controllers:  # it was replaced without a word
            raise ValueError(f"world_options: controllers of '{self.model}', the agents' model: "
                             f"the environment's actions drive it (controllers are for other "
                             f"models)")
        controllers[self.model] = self._controller(slot)
        if not self.spec["keep_scripts"]:
            if not has_keep_scripts():
                raise ValueError("keep_scripts=False: this build's swarmsim.World has no "
                                 "keep_scripts; use a world whose models entry has a "
                                 "python_controller (its Lua scripts are dropped), such as "
                                 "worlds/python/diffusion_numpy.yaml")
            options["keep_scripts"] = False
        slot.world = World(self.path, seed=seed, set=self.spec["set"],
                           threads=self.spec["threads"], controllers=controllers, **options)
        slot.seed = seed
        return slot.world

    def _map(self, k):
        """Where each agent is in the model's arrays (after a load or reset)."""
        slot = self.slots[k]
        robots = slot.world.robots
        indices = [i for i, m in zip(robots["indices"], robots["models"]) if m == self.model]
        names = [n for n, m in zip(robots["names"], robots["models"]) if m == self.model]
        self._remap(slot, indices, names)

    def _remap(self, slot, indices, names):
        slot.indices = list(indices)
        row_of = np.full(len(self.agents), -1, dtype=np.int64)
        for row, name in enumerate(names):
            i = self.agent_index.get(name)
            if i is not None:
                row_of[i] = row
        slot.row_of = row_of
        slot.identity = len(names) == len(self.agents) and bool(
            np.array_equal(row_of, np.arange(len(self.agents))))
        old = slot.targets
        slot.targets = np.zeros((len(self.joint_names), len(names)))
        if old is not None and old.shape == slot.targets.shape:
            slot.targets[:] = old

    def reset_world(self, k, seed=None, poses=None):
        """Puts world k at the start of an episode (not yet stepped: the caller's next
        step_all() is its first, with every joint target 0). seed None: the world's next
        seed (base seed + k the first time, then drawn from the last seed). poses: the
        agents' robots' poses (N, 3 or 7), through World.set_poses."""
        slot = self.slots[k]
        if seed is None:
            if slot.rng is None:
                seed = self.base_seed + k
            else:
                seed = int(slot.rng.integers(MAX_SEED))
        seed = int(seed)
        if seed < 0:
            raise ValueError(f"seed must be >= 0, got {seed}")
        if poses is not None:
            poses = self.checked_poses(poses)  # before the world changes
        slot.rng = np.random.default_rng(seed)
        if slot.fresh and slot.seed == seed:
            pass  # loaded with this seed and never stepped
        elif slot.world is not None and has_reset():
            try:
                slot.world.reset(seed=seed)
            except RuntimeError as e:
                # A world stopped by an error, or one World.reset cannot put back (a module
                # that cannot save its state): load it again, and say so once.
                if not self.reset_failures:
                    warnings.warn(f"{self.path}: World.reset failed ({e}); the environment "
                                  f"loads the world again instead", RuntimeWarning, stacklevel=3)
                self.reset_failures += 1
                self._load(k, seed)
        else:
            self._load(k, seed)
        slot.fresh = False
        slot.seed = seed
        self._map(k)
        if poses is not None:
            setter = getattr(slot.world, "set_poses", None)
            if setter is None:
                raise ValueError("reset(options={'poses': ...}) needs World.set_poses, which "
                                 "this build of swarmsim does not have")
            if not slot.identity:
                raise ValueError(f"reset: options['poses'] must have one row per agent "
                                 f"({self.N}, 3 or 7), got shape {poses.shape}")
            setter(self.model, poses)
        slot.targets[:] = 0
        self.episode_steps[k] = 0
        self.last_actions[k] = 0
        self.present[k] = slot.row_of >= 0
        self.active[k] = self.present[k]
        self.terminated[k] = False
        self.truncated[k] = False
        self.rewards[k] = 0

    def checked_poses(self, poses):
        # What World.set_poses would refuse, refused before a reset begins: a failed
        # reset(options=...) leaves the environment as it was.
        if isinstance(poses, (str, bytes)):
            raise TypeError(f"reset: options['poses'] must be an array, not {type(poses).__name__}")
        array = np.asarray(poses)
        if array.dtype.kind not in "iuf":
            raise TypeError(f"reset: options['poses'] must be numbers, got dtype {array.dtype}")
        array = array.astype(np.float64)
        if array.ndim != 2 or array.shape[0] != self.N or array.shape[1] not in (3, 7):
            raise ValueError(f"reset: options['poses'] must have one row per agent "
                             f"({self.N}, 3 or 7), got shape {array.shape}")
        bad = ~np.isfinite(array).all(axis=1)
        if bad.any():
            i = int(np.argmax(bad))
            raise ValueError(f"reset: options['poses'] row {i} ('{self.agents[i]}') is not finite")
        position = array[:, :2] if array.shape[1] == 3 else array[:, :3]
        far = (np.abs(position) > _swarmsim.MAX_COORDINATE).any(axis=1)
        if far.any():
            i = int(np.argmax(far))
            raise ValueError(f"reset: options['poses'] row {i} ('{self.agents[i]}') is beyond "
                             f"+-1e6 m, the largest coordinate a world may use")
        return array

    def set_actions(self, ks, actions):
        """Joint targets of the next step of worlds ks from their actions (len(ks), N, A),
        already checked; inactive agents' rows count as 0."""
        acts = np.where(self.active[ks][..., None], actions, 0.0)
        self.last_actions[ks] = acts
        targets = self.actions.targets(acts)  # (len(ks), N, J)
        for j, k in enumerate(ks):
            self._write_targets(self.slots[k], targets[j])

    def _write_targets(self, slot, targets):
        # targets (N, J) in agent order -> the slot's (J, rows).
        if slot.identity:
            slot.targets[:] = targets.T
        else:
            slot.targets[:] = 0
            has = slot.row_of >= 0
            slot.targets[:, slot.row_of[has]] = targets[has].T

    def step_list(self, worlds):
        step_worlds(worlds, 1, self.spec["step_threads"], self.parallel)

    def step_all(self, counted=None):
        """Steps every world once. counted (K,) bools: the worlds whose episodes count the
        step (None: none, a reset's step), by the steps the worlds took, so that an observation,
        reward or Ctrl-C that raises after (or during) it leaves the count right."""
        for slot in self.slots:
            slot.called = False
        before = [s.world.steps for s in self.slots]
        try:
            self.step_list([s.world for s in self.slots])
        finally:
            for k, slot in enumerate(self.slots):
                if counted is not None and counted[k]:
                    self.episode_steps[k] += slot.world.steps - before[k]
        for slot in self.slots:
            if not slot.called and slot.indices:
                self._remap(slot, [], [])  # the model's robots are gone

    def observe(self):
        """Reads every world's observations and poses into obs (K, N, D) and poses."""
        self.previous_poses[:] = self.poses
        for k, slot in enumerate(self.slots):
            w = slot.world
            if slot.identity:
                for (item, _, _, _), raw in zip(self.blocks, self.raw):
                    view = raw[k]
                    got = item.read(w, self.model, view)
                    if got is not view:
                        view[...] = _read_shape(item, got, view.shape)
                view = self.poses[k]
                got = w.poses(self.model, out=view)
                if got is not view:
                    view[...] = got
            else:
                has = slot.row_of >= 0
                rows = slot.row_of[has]
                for (item, width, _, _), raw in zip(self.blocks, self.raw):
                    got = item.read(w, self.model, None)
                    got = _read_shape(item, got, (None, width))  # robots come and go
                    if len(rows):
                        raw[k][has] = got[rows]
                if len(rows):
                    self.poses[k][has] = w.poses(self.model)[rows]
            self.present[k] = slot.row_of >= 0
        for (item, _, a, b), raw in zip(self.blocks, self.raw):
            self.obs[:, :, a:b] = item.transform(raw)
            self._check_not_nan(item, a, b)
        # Agents whose robot is gone keep their last observation.

    def _check_not_nan(self, item, a, b):
        # inf is a reading (a ray that sees nothing); NaN is a broken block, which a
        # learner would take in silently.
        block = self.obs[:, :, a:b]
        if not np.isnan(block).any():
            return
        k, i, c = (int(v) for v in np.argwhere(np.isnan(block))[0])
        where = f" of environment {k}" if self.K > 1 else ""
        raise ValueError(f"observation '{item.name}': column {c} is NaN for agent "
                         f"'{self.agents[i]}'{where} (after {int(self.episode_steps[k])} "
                         f"steps of the episode); read() or transform() must return numbers")

    def agent_arrays(self, k):
        arrays = AgentArrays()
        arrays.names = self.agents
        arrays.active = self.active[k]
        arrays.present = self.present[k]
        arrays.observations = self.obs[k]
        arrays.actions = self.last_actions[k]
        arrays.poses = self.poses[k]
        arrays.previous_poses = self.previous_poses[k]
        arrays.step = int(self.episode_steps[k])
        arrays.env = k
        arrays.model = self.model
        return arrays

    def score(self, mask):
        """After a step of the worlds of mask (K,) bools (not a reset's step): their
        rewards, terminations and truncations, and the agents still active."""
        ks = np.flatnonzero(mask)
        if not len(ks):
            return
        acting = self.active[ks]
        reward = self.spec["reward"]
        terminate = self.spec["terminate"]
        batched = getattr(reward, "batched", None)
        rewards = batched(self, ks) if batched is not None else np.zeros((len(ks), self.N))
        done = ~self.present[ks] & acting  # robots removed from the world
        if batched is None or terminate is not None:
            for j, k in enumerate(ks):
                world = self.slots[k].world
                arrays = self.agent_arrays(k)
                arrays.active = acting[j]
                steps = world.steps
                if batched is None:
                    self.in_callback = "reward"
                    try:
                        rewards[j] = reward(world, arrays, self, k)
                    finally:
                        self.in_callback = None
                if terminate is not None:
                    self.in_callback = "terminate"
                    try:
                        done[j] |= _bools(terminate(world, arrays), self.N, "terminate")
                    finally:
                        self.in_callback = None
                if world.steps != steps:  # its episode's count and flags would be wrong
                    raise RuntimeError(
                        f"the reward or terminate function stepped the world ({steps} -> "
                        f"{world.steps} steps): read it there, the environment steps it")
        terminated = done & acting
        # True from its step until the world resets; an agent whose robot was gone before
        # it ever acted (removed in the reset's first step) too, from the episode's first.
        self.terminated[ks] |= terminated | ~self.present[ks]
        if self.max_steps is not None:
            limit = (self.episode_steps[ks] >= self.max_steps)[:, None]
            self.truncated[ks] = acting & ~terminated & limit
        else:
            self.truncated[ks] = False
        self.rewards[ks] = np.where(acting, rewards, 0.0)
        self.active[ks] = acting & ~terminated & ~self.truncated[ks]

    def close(self):
        for slot in self.slots:
            if slot.world is not None:
                slot.world.close()
                slot.world = None
        self.closed = True


def _read_shape(item, got, shape):
    """`got`, a read() result, as an array of exactly `shape` (None: any length there; no
    broadcasting: a block whose width changed would be filled with the wrong columns)."""
    array = np.asarray(got)
    if np.iscomplexobj(array):
        raise TypeError(f"observation '{item.name}': read() returned complex numbers")
    if array.ndim != len(shape) or any(want is not None and got_n != want
                                       for got_n, want in zip(array.shape, shape)):
        expected = tuple("robots" if n is None else n for n in shape)
        raise ValueError(f"observation '{item.name}': read() returned shape {array.shape}, "
                         f"expected {expected} (one row per robot, as many columns as its "
                         f"first read)")
    return array


def _file_seed(world):
    match = re.search(r"\bseed (\d+)", world.describe())
    return int(match.group(1)) if match else 0


def _bools(values, n, what):
    values = np.asarray(values)
    if values.dtype != bool:
        raise ValueError(f"{what}: the function must return booleans (one per agent or one for "
                         f"all), got dtype {values.dtype}")
    return np.broadcast_to(values, (n,)) if values.shape in ((), (1,), (n,)) else _shape_error(
        what, values.shape, n)


def _shape_error(what, shape, n):
    raise ValueError(f"{what}: the function must return one value per agent ({n},) or one "
                     f"for all, got shape {shape}")
