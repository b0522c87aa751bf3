"""Multi-agent environments over a swarmsim world: every robot of one model is an agent.

    import numpy as np
    from swarmsim.env import ParallelEnv
    env = ParallelEnv("worlds/python/diffusion_numpy.yaml", set={"robots": 16}, max_steps=200)
    obs, infos = env.reset(seed=1)                       # {agent: (24,) proximity nearness}
    while env.agents:
        actions = {a: env.action_space(a).sample() for a in env.agents}   # 2 wheel speeds, m/s
        obs, rewards, terminations, truncations, infos = env.step(actions)
    env.close()

``ParallelEnv`` has the shape of PettingZoo's Parallel API (dicts keyed by agent name);
``VectorEnv`` runs K copies of the world as arrays, (K, N, D) observations and (K, N, A)
actions, with Gymnasium's vector conventions and next-step autoreset. Both take the same
declarations:

- ``observations``: a list of blocks concatenated per agent, each a name (``"proximity"``,
  ``"proximity_distance"``, ``"proximity_values"``, ``"ground"``, ``"light"``, ``"pose"``,
  ``"velocity"``, ``"joint_positions"``, ``"joint_velocities"``, ``"range_and_bearing"``),
  the same built by a function of this module with its arguments (``proximity(range=0.1)``,
  ``range_and_bearing(neighbours=4)``), or an ``Observation(name, read, low, high)`` of your own.
  Default: ``["proximity"]``.
- ``actions``: ``JointTargets(joints, low, high, scale)``: one action per joint, the joint's
  target (velocity for velocity-mode joints, position for position-mode ones) = action x scale.
  Default: ``wheel_speeds()``: the model's joints as wheels, in m/s within +-0.1 m/s, divided by
  the foot-bot's wheel radius (0.029 m).
- ``reward``: ``"distance"`` (default: metres each agent moved in the step), a metric name of
  the world's ``metrics:`` (a robot-level metric per agent, a swarm-level one shared; 0 until
  it has a value), or a function ``reward(world, agents) -> (N,) array or number`` called
  after each step with an :class:`AgentArrays` (``agents.observations``, ``agents.poses``,
  ``agents.previous_poses``, ``agents.actions``, ``agents.active``, ``agents.step``, ...).
- ``terminate``: ``None`` or ``terminate(world, agents) -> (N,) bools or one bool``: agents for
  which it is True leave (a robot removed from the world leaves too). ``max_steps``: the
  episode is truncated after this many steps (default ``"world"``: the world's duration;
  ``None``: never).

See swarm/python/README.md for the full reference.
"""

import functools
import threading
import warnings
from collections.abc import Mapping

import numpy as np

from . import spaces
from ._env_core import (AgentArrays, Core, has_keep_scripts, has_parallel_step, has_reset,
                        step_worlds, whole_number)

__all__ = [
    "ParallelEnv", "VectorEnv", "Observation", "JointTargets", "AgentArrays", "wheel_speeds",
    "proximity", "proximity_distance", "proximity_values", "ground", "light", "pose",
    "velocity", "joint_positions", "joint_velocities", "range_and_bearing", "step_worlds",
    "has_parallel_step", "has_reset", "has_keep_scripts",
]

INF = float("inf")


# --- Observations ----------------------------------------------------------------------

class Observation:
    """One block of every agent's observation.

    ``Observation(name, read, low=-inf, high=inf, transform=None)``: ``read(world, model)``
    returns a (robots, columns) float array, one row per robot of ``model`` in index order
    (the order of ``world.poses(model)``); ``transform(raw)``, if given, maps the raw
    (..., columns) array to the block's values (called on all K worlds' rows at once, so it
    must work on any leading dimensions); ``low``/``high`` bound the block (numbers or one
    per column; the spaces say them; values are not clipped to them)."""

    def __init__(self, name, read, low=-INF, high=INF, transform=None, takes_out=False):
        if not callable(read):
            raise TypeError(f"Observation '{name}': read must be a function (world, model)")
        self.name = name
        self._read = read
        self._takes_out = takes_out
        self.low = low
        self.high = high
        self._transform = transform

    def read(self, world, model, out):
        """The raw (robots, columns) array; written into out when it fits."""
        if self._takes_out:
            return self._read(world, model, out)
        return self._read(world, model)

    def transform(self, raw):
        return raw if self._transform is None else self._transform(raw)

    def low_for(self, width):
        return _bound(self.low, width, f"observation '{self.name}': low")

    def high_for(self, width):
        return _bound(self.high, width, f"observation '{self.name}': high")

    def __repr__(self):
        return f"Observation({self.name!r})"


def _bound(value, width, what):
    value = np.asarray(value, dtype=np.float64)
    if value.ndim == 0:
        return np.full(width, float(value))
    if value.shape != (width,):
        raise ValueError(f"{what} has shape {value.shape}, the block has {width} columns")
    return value


def proximity(range=0.1):
    """Each proximity sensor's nearness, 1 - distance / range, in [0, 1]: 0 where it sees
    nothing, 1 touching (range: the sensors' range in m; the foot-bot's is 0.1)."""
    if not range > 0:
        raise ValueError(f"proximity(range=...) must be > 0, got {range}")

    def transform(d):
        return np.clip(1.0 - d / range, 0.0, 1.0)  # inf (nothing seen) -> 0
    return Observation("proximity", lambda w, m, out: w.proximity(m, out=out), 0.0, 1.0,
                       transform, takes_out=True)


def proximity_distance():
    """Each proximity sensor's distance in m, inf where it sees nothing."""
    return Observation("proximity_distance", lambda w, m, out: w.proximity(m, out=out), 0.0,
                       INF, takes_out=True)


def proximity_values():
    """Each proximity sensor's value on its response curve (the e-puck's IR), 0 for sensors
    without one."""
    return Observation("proximity_values", lambda w, m, out: w.proximity_values(m, out=out),
                       -INF, INF, lambda v: np.nan_to_num(v, nan=0.0), takes_out=True)


def ground():
    """Each ground sensor's value (grey level, 0/1 in binary mode), in [0, 1]."""
    return Observation("ground", lambda w, m, out: w.ground(m, out=out), 0.0, 1.0,
                       takes_out=True)


def light():
    """Each light sensor's reading (>= 0)."""
    return Observation("light", lambda w, m, out: w.light(m, out=out), 0.0, INF, takes_out=True)


def _heading(q):
    # x, y, and the heading's cosine and sine from the quaternion (the body's x axis in the
    # plane): plain arithmetic, so equal runs give equal bits (numpy's SIMD sin/cos may round
    # differently depending on where an array lies in memory).
    w, x, y, z = q[..., 3], q[..., 4], q[..., 5], q[..., 6]
    cos_yaw = np.clip(1.0 - 2.0 * (y * y + z * z), -1.0, 1.0)
    sin_yaw = np.clip(2.0 * (x * y + w * z), -1.0, 1.0)
    return np.stack([q[..., 0], q[..., 1], cos_yaw, sin_yaw], axis=-1)


def pose():
    """The robot's x, y (m) and its heading as cos, sin."""
    return Observation("pose", lambda w, m, out: w.poses(m, out=out, columns=7),
                       [-INF, -INF, -1.0, -1.0], [INF, INF, 1.0, 1.0], _heading, takes_out=True)


def velocity():
    """The robot's linear (m/s) and angular (rad/s) velocity, 6 columns."""
    return Observation("velocity", lambda w, m, out: w.velocities(m, out=out), takes_out=True)


def joint_positions():
    """Each joint's position (rad or m), the model's joint order."""
    return Observation("joint_positions", lambda w, m, out: w.joint_positions(m, out=out),
                       takes_out=True)


def joint_velocities():
    """Each joint's velocity, the model's joint order."""
    return Observation("joint_velocities", lambda w, m, out: w.joint_velocities(m, out=out),
                       takes_out=True)


_MAX_NEIGHBOURS = 10000

# An environment is used by one thread at a time (as Gymnasium's and PettingZoo's are): a
# second thread calling in while one is inside is refused, not interleaved (two threads
# stepping one VectorEnv lost steps and desynchronised its episodes). One lock for every
# environment guards the check; the environment holds only the caller's thread id.
_CALLS = threading.Lock()


def _one_thread_at_a_time(method):
    @functools.wraps(method)
    def call(self, *args, **kwargs):
        me = threading.get_ident()
        core = self.__dict__.get("_core")
        if core is not None and getattr(core, "in_callback", None):
            raise RuntimeError(
                f"{type(self).__name__}.{method.__name__}(): called from inside the "
                f"environment's own {core.in_callback} function, which runs within a step; "
                f"call it after step() returns")
        with _CALLS:
            owner, depth = self.__dict__.get("_caller", (None, 0))
            if owner is not None and owner != me:
                raise RuntimeError(
                    f"{type(self).__name__}.{method.__name__}(): another thread is inside a "
                    f"call of this environment; use each environment from one thread at a "
                    f"time (one environment per thread, or a lock around its calls)")
            self.__dict__["_caller"] = (me, depth + 1)
        try:
            return method(self, *args, **kwargs)
        finally:
            with _CALLS:
                owner, depth = self.__dict__["_caller"]
                self.__dict__["_caller"] = (None, 0) if depth == 1 else (owner, depth - 1)
    return call


def _world_options(options):
    """world_options as a new dict: World's own arguments the environment does not set
    itself (it gave pybind11's "got multiple values for keyword argument 'seed'")."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise TypeError(f"world_options must be a dict (or None), got {type(options).__name__}")
    options = dict(options)
    for key, instead in (("path", "the environment's world"), ("seed", "reset(seed=...)"),
                         ("set", "set="), ("threads", "threads=")):
        if key in options:
            raise ValueError(f"world_options: '{key}' is the environment's own: use {instead}")
    return options


def _options(options):
    """reset's options as a new dict: a mapping or None, else TypeError."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise TypeError(f"reset: options must be a dict (or None), got "
                        f"{type(options).__name__}")
    return dict(options)


def _count(value, what, minimum=0):
    """`value` as an int: a whole number (an int, or a float such as 100.0; not a bool or a
    string) of at least `minimum`; else TypeError or ValueError naming `what`."""
    if isinstance(value, (float, np.floating)) and np.isfinite(value) and value == int(value):
        value = int(value)
    return whole_number(value, what, minimum)


def range_and_bearing(neighbours=4):
    """What the robot's first range-and-bearing board heard, the nearest `neighbours` first:
    for each, (heard 0/1, range m, bearing rad in [-pi, pi]); zeros past what it heard."""
    k = _count(neighbours, "range_and_bearing(neighbours=...)", minimum=1)
    if k > _MAX_NEIGHBOURS:
        raise ValueError(f"range_and_bearing(neighbours=...) must be 1 to {_MAX_NEIGHBOURS} "
                         f"(3 columns each per robot), got {neighbours}")

    def read(world, model):
        rab = world.range_and_bearing(model)
        offsets = rab["offsets"]
        n = len(offsets) - 1
        out = np.zeros((n, 3 * k))
        counts = np.diff(offsets)
        for j in range(k):
            has = counts > j
            at = offsets[:-1][has] + j
            out[has, 3 * j] = 1.0
            out[has, 3 * j + 1] = rab["range"][at]
            out[has, 3 * j + 2] = rab["bearing"][at]
        return out
    low = np.tile([0.0, 0.0, -np.pi], k)
    high = np.tile([1.0, INF, np.pi], k)
    return Observation("range_and_bearing", read, low, high)


_OBSERVATIONS = {
    "proximity": proximity, "proximity_distance": proximity_distance,
    "proximity_values": proximity_values, "ground": ground, "light": light, "pose": pose,
    "velocity": velocity, "joint_positions": joint_positions,
    "joint_velocities": joint_velocities, "range_and_bearing": range_and_bearing,
}


def _observation(item):
    if isinstance(item, Observation):
        return item
    if isinstance(item, str):
        make = _OBSERVATIONS.get(item)
        if make is None:
            raise ValueError(f"observations: no block '{item}' (known: "
                             f"{', '.join(_OBSERVATIONS)}; or an Observation of your own)")
        return make()
    if callable(item):
        return Observation(getattr(item, "__name__", "custom"), item)
    raise TypeError(f"observations: each block is a name, an Observation or a function "
                    f"(world, model) -> array, got {item!r}")


# --- Actions ---------------------------------------------------------------------------

class JointTargets:
    """Actions as joint targets: one action per joint of ``joints`` (default: every joint of
    the model, in its order), each in [low, high] (numbers or one per joint); the joint's
    target is action x scale (velocity for velocity-mode joints, position for position-mode
    ones). The model's other joints keep what its scripts set."""

    def __init__(self, joints=None, low=-1.0, high=1.0, scale=1.0):
        self.joints = None if joints is None else [str(j) for j in joints]
        self.low, self.high, self.scale = low, high, scale

    def bind(self, joint_names, model):
        joints = list(joint_names) if self.joints is None else self.joints
        twice = sorted({j for j in joints if joints.count(j) > 1})
        if twice:
            raise ValueError(f"actions: joint {twice} listed twice (one action per joint)")
        unknown = [j for j in joints if j not in joint_names]
        if unknown:
            raise ValueError(f"actions: model '{model}' has no joint {unknown} "
                             f"(its joints: {list(joint_names)})")
        if not joints:
            raise ValueError(f"actions: model '{model}' has no joints to drive")
        bound = JointTargets(joints, self.low, self.high, self.scale)
        n = len(joints)
        bound.size = n
        bound.low = _bound(self.low, n, "actions: low")
        bound.high = _bound(self.high, n, "actions: high")
        bound.scale = _bound(self.scale, n, "actions: scale")
        if np.any(bound.low > bound.high) or not np.all(np.isfinite(bound.low)) or not np.all(
                np.isfinite(bound.high)):
            raise ValueError(f"actions: bounds must be finite with low <= high, got "
                             f"low={self.low}, high={self.high}")
        with np.errstate(over="ignore", invalid="ignore"):
            finite = np.isfinite(bound.scale) & np.isfinite(bound.low * bound.scale) & np.isfinite(
                bound.high * bound.scale)
        if not np.all(finite):
            raise ValueError(f"actions: scale must be finite, and low x scale and high x scale "
                             f"too, got scale={self.scale}")
        return bound

    def targets(self, actions):
        """(N, joints) targets of (N, joints) actions."""
        return actions * self.scale


def wheel_speeds(max_speed=0.1, wheel_radius=0.029, joints=None):
    """Differential-drive actions: each wheel's speed at its rim in m/s, within
    +-max_speed, turned into the wheel joint's target velocity (rad/s) by wheel_radius (m).
    Defaults: the foot-bot's (worlds/models/footbot.yaml: wheel_radius 0.029 m)."""
    if not max_speed > 0 or not wheel_radius > 0:
        raise ValueError("wheel_speeds: max_speed and wheel_radius must be > 0")
    return JointTargets(joints, -max_speed, max_speed, 1.0 / wheel_radius)


# --- Rewards ---------------------------------------------------------------------------

def _distance_reward(world, agents, core, k):
    return _distance_reward.batched(core, [k])[0]


def _distance_batched(core, ks):
    # Metres each agent's robot moved in the step (0 for robots gone), all worlds at once.
    d = core.poses[ks, :, :2] - core.previous_poses[ks, :, :2]
    return np.where(core.present[ks], np.sqrt(d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1]),
                    0.0)


_distance_reward.batched = _distance_batched


# Steps a robot-level metric reward may go unrecorded before a warning that its name may
# be misspelt (it is 0 until the robots record it).
_UNRECORDED_METRIC_STEPS = 100


def _metric_reward(name):
    unrecorded = [0]  # steps without a value; -1 once warned or seen

    def reward(world, agents, core, k):
        metrics = world.metrics
        if name in metrics:
            value = float(metrics[name])
            return np.full(core.N, value if np.isfinite(value) else 0.0)
        try:
            values = np.asarray(world.robot_metric(name), dtype=np.float64)
        except KeyError as e:  # no robot has recorded it yet (sim.recordMetric from a later step)
            if unrecorded[0] >= 0 and k == 0:  # a step of the first environment: one a step
                unrecorded[0] += 1
                if unrecorded[0] >= _UNRECORDED_METRIC_STEPS:
                    unrecorded[0] = -1
                    warnings.warn(f"reward: no robot has recorded metric '{name}' in "
                                  f"{_UNRECORDED_METRIC_STEPS} steps, so every reward is 0: is it "
                                  f"the name the scripts record? ({e.args[0]})", stacklevel=2)
            return np.zeros(core.N)
        unrecorded[0] = -1
        robots = world.robots
        mine = values[[i for i, m in enumerate(robots["models"]) if m == core.model]]
        out = np.zeros(core.N)
        row_of = core.slots[k].row_of
        has = (row_of >= 0) & (row_of < len(mine))
        out[has] = mine[row_of[has]]
        return np.nan_to_num(out, nan=0.0)
    reward.metric = name
    return reward


def _function_reward(fn):
    def reward(world, agents, core, k):
        returned = fn(world, agents)
        if returned is None:  # numpy reads it as NaN: "not finite" said nothing of the cause
            raise TypeError("reward: the function returned None: return one reward per agent "
                            "or one for all")
        try:
            values = np.asarray(returned, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise TypeError(f"reward: the function must return numbers (one per agent, or "
                            f"one for all), got {type(returned).__name__}: {e}") from None
        if values.shape not in ((), (1,), (core.N,)):
            raise ValueError(f"reward: the function must return one reward per agent "
                             f"({core.N},) or one for all, got shape {values.shape}")
        values = np.broadcast_to(values, (core.N,))
        if not np.all(np.isfinite(values[agents.active])):
            raise ValueError("reward: the function returned a reward that is not finite")
        return values
    return reward


def _reward(reward):
    if reward is None or reward == "distance":
        return _distance_reward
    if isinstance(reward, str):
        return _metric_reward(reward)
    if callable(reward):
        return _function_reward(reward)
    raise TypeError(f"reward: 'distance', a metric name or a function (world, agents), "
                    f"got {reward!r}")


def _flag(value, name):
    """A True/False argument: bool() took clip_actions="no" as True."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise TypeError(f"{name} must be True or False, got {value!r}")


def _spec(world, observations, actions, reward, terminate, max_steps, model, seed, set,
          threads, world_options, keep_scripts=True, step_threads=0):
    if observations is None:
        observations = ["proximity"]
    if isinstance(observations, (str, Observation)) or callable(observations):
        observations = [observations]
    if actions is None:
        actions = wheel_speeds()
    if not isinstance(actions, JointTargets):
        raise TypeError(f"actions: a JointTargets (or wheel_speeds()), got {actions!r}")
    if terminate is not None and not callable(terminate):
        raise TypeError("terminate: a function (world, agents) -> bools, or None")
    if max_steps is not None and not (isinstance(max_steps, str) and max_steps == "world"):
        max_steps = _count(max_steps, "max_steps (a number of steps, 'world' or None)",
                           minimum=1)
    step_threads = _count(step_threads, "step_threads (0: every core)")
    if step_threads > 256:
        raise ValueError(f"step_threads is 0 (every core) or 1 to 256, got {step_threads}")
    if seed is not None:
        seed = whole_number(seed, "seed")
    world_options = _world_options(world_options)
    return {
        "world": world, "observations": [_observation(o) for o in observations],
        "actions": actions, "reward": _reward(reward), "terminate": terminate,
        "max_steps": max_steps, "model": model, "seed": seed, "set": dict(set or {}),
        "threads": threads, "world_options": world_options,
        "keep_scripts": _flag(keep_scripts, "keep_scripts"), "step_threads": int(step_threads),
    }


def _check_actions(core, acts, name_of, clip):
    """Checks (M, A) actions against the bounds; returns them as float64 (clipped if clip).
    name_of(m) names the agent of row m in errors."""
    acts = np.asarray(acts)
    if acts.dtype.kind not in "iuf":
        raise ValueError(f"actions must be real numbers, got dtype {acts.dtype}")
    bounds = core.actions
    if not clip:
        # Compared in the actions' own precision: float32(0.1) is in [-0.1, 0.1].
        low = bounds.low.astype(acts.dtype) if acts.dtype.kind == "f" else bounds.low
        high = bounds.high.astype(acts.dtype) if acts.dtype.kind == "f" else bounds.high
        bad = ~((acts >= low) & (acts <= high)).all(axis=-1)  # NaN is outside
        if bad.any():
            m = int(np.argmax(bad))
            # NaN is no value to clip: clip_actions=True refuses it too.
            hint = ("(NaN is refused with clip_actions=True too)" if np.isnan(acts[m]).any()
                    else "(pass clip_actions=True to clip)")
            raise ValueError(
                f"action {acts[m].tolist()} for {name_of(m)} is outside the action space: "
                f"each of {bounds.joints} in [{_fmt(bounds.low)}, {_fmt(bounds.high)}] {hint}")
    clipped = np.clip(acts.astype(np.float64), bounds.low, bounds.high)
    if clip:
        # NaN stays an error; +-inf is clipped like any value past a bound (it was
        # refused). The bounds are finite (JointTargets.bind), so only NaN is left here.
        bad = ~np.isfinite(clipped).all(axis=-1)
        if bad.any():
            m = int(np.argmax(bad))
            raise ValueError(f"action {acts[m].tolist()} for {name_of(m)} is not finite")
    return clipped


def _fmt(values):
    values = np.unique(values)
    return f"{values[0]:g}" if values.size == 1 else str(values.tolist())


class _AgentsOfAModel:
    """What both environments say of their agents' model (their `_core` holds it)."""

    @property
    def model(self):
        """The name of the model whose robots are the agents."""
        return self._core.model

    @property
    def joint_names(self):
        """The joints the actions drive, in action order."""
        return list(self._core.actions.joints)

    # An environment is its worlds and the controllers they call back: a copy's worlds
    # would report to the original (copy.deepcopy made one whose agents all ended at its
    # first step, reward 0, with no error). Make another from the same arguments.
    def _not_copied(self, what):
        raise TypeError(f"{type(self).__name__} cannot be {what}: make another one with the "
                        f"same arguments (in each process), or snapshot its worlds "
                        f"(World.snapshot)")

    def __copy__(self):
        self._not_copied("copied")

    def __deepcopy__(self, memo):
        self._not_copied("copied")

    def __reduce_ex__(self, protocol):
        self._not_copied("pickled")


# --- The PettingZoo-style environment ----------------------------------------------------

class _ParallelFallback:
    """What PettingZoo's ParallelEnv gives its subclasses, for when it is not installed."""

    @property
    def unwrapped(self):
        """The environment itself (no wrapper around it)."""
        return self


try:  # a subclass of PettingZoo's ParallelEnv when PettingZoo is installed
    from pettingzoo import ParallelEnv as _ParallelBase
except ImportError:
    _ParallelBase = _ParallelFallback


class ParallelEnv(_AgentsOfAModel, _ParallelBase):
    """Every robot of one model of a world is an agent; all act at once (PettingZoo's Parallel
    API: ``reset(seed=None, options=None) -> (observations, infos)``, ``step(actions) ->
    (observations, rewards, terminations, truncations, infos)``, dicts keyed by agent name).

    ``ParallelEnv(world, observations=None, actions=None, reward=None, terminate=None,
    max_steps="world", model=None, seed=None, set=None, threads=0, clip_actions=False,
    world_options=None)``: ``world`` a world file; ``model`` the model whose robots are the
    agents (default: the world's only model with joints); ``seed`` the first episode's seed
    (default: the world file's); ``set``, ``threads`` as for ``swarmsim.World``;
    ``world_options`` more keyword arguments for ``swarmsim.World`` (``package_path``,
    ``controllers`` of other models). The declarations are described in the module's doc.
    """

    metadata = {"name": "swarmsim_parallel_v0", "render_modes": [], "is_parallelizable": True}
    render_mode = None

    def __init__(self, world, observations=None, actions=None, reward=None, terminate=None,
                 max_steps="world", model=None, seed=None, set=None, threads=0,
                 clip_actions=False, keep_scripts=True, world_options=None):
        spec = _spec(world, observations, actions, reward, terminate, max_steps, model, seed,
                     set, threads, world_options, keep_scripts)
        self._core = Core(spec, 1)
        self._clip = _flag(clip_actions, "clip_actions")
        core = self._core
        self.possible_agents = list(core.agents)
        self.agents = []
        self.observation_spaces = {a: self._obs_space() for a in self.possible_agents}
        self.action_spaces = {a: spaces.Box(core.actions.low, core.actions.high, (core.A,),
                                            np.float64) for a in self.possible_agents}
        # PettingZoo's state_space: what state() returns, N x D values in one row.
        n = len(self.possible_agents)
        self.state_space = spaces.Box(np.tile(core.obs_low, n), np.tile(core.obs_high, n),
                                      (n * core.D,), np.float64)
        self._started = False

    def _obs_space(self):
        core = self._core
        return spaces.Box(core.obs_low, core.obs_high, (core.D,), np.float64)

    @property
    def world(self):
        """The swarmsim.World being stepped (read any array from it; do not step it)."""
        if self._core.closed:
            raise RuntimeError("the environment is closed")
        return self._core.slots[0].world

    @property
    def num_agents(self):
        return len(self.agents)

    @property
    def max_num_agents(self):
        return len(self.possible_agents)

    @property
    def max_steps(self):
        """Steps after which an episode is truncated (None: never)."""
        return self._core.max_steps

    def observation_space(self, agent):
        """The Box of one agent's observations (the same object for the same agent)."""
        try:
            return self.observation_spaces[agent]
        except KeyError:
            raise KeyError(f"no agent {agent!r} (agents are {self.possible_agents[:3]}...)")

    def action_space(self, agent):
        """The Box of one agent's actions (the same object for the same agent)."""
        try:
            return self.action_spaces[agent]
        except KeyError:
            raise KeyError(f"no agent {agent!r} (agents are {self.possible_agents[:3]}...)")

    @_one_thread_at_a_time
    def reset(self, seed=None, options=None):
        """Starts an episode: the world at its start (seed: its seed; None: the world file's
        the first time, then one drawn from the last seed) after one step with every joint
        target 0, so that the sensors have read. options={"poses": (N, 3) x, y, yaw or
        (N, 7)} places the agents' robots first (World.set_poses, in builds that have it).
        Returns (observations, infos)."""
        if self._core.closed:
            raise RuntimeError("the environment is closed")
        options = _options(options)
        poses = options.pop("poses", None)
        if options:
            raise ValueError(f"reset: unknown options {sorted(options)} (known: 'poses')")
        if seed is not None:
            seed = whole_number(seed, "reset: seed")
        core = self._core
        core.reset_world(0, seed, poses)
        core.step_all()
        core.observe()
        core.present[0] = core.slots[0].row_of >= 0
        core.active[0] = core.present[0]
        self.agents = [a for a, on in zip(self.possible_agents, core.active[0]) if on]
        self._started = True
        obs = core.obs[0]
        index = core.agent_index
        return {a: obs[index[a]].copy() for a in self.agents}, {a: {} for a in self.agents}

    @_one_thread_at_a_time
    def step(self, actions):
        """One step of the world with one action per live agent (a dict {agent: array of
        the action space's shape}). Returns (observations, rewards, terminations,
        truncations, infos), each keyed by the agents that were live before the step; the
        agents terminated or truncated leave ``agents``."""
        core = self._core
        if core.closed:
            raise RuntimeError("the environment is closed")
        if not self._started:
            raise RuntimeError("call reset() before step()")
        if not self.agents:
            raise RuntimeError("every agent is done: call reset() to start a new episode")
        if not isinstance(actions, dict):
            raise TypeError(f"step(actions): a dict {{agent: action}}, got "
                            f"{type(actions).__name__}")
        live = self.agents
        index = core.agent_index
        unknown = [a for a in actions if a not in index]
        if unknown:
            raise KeyError(f"step: no agent {unknown[0]!r}")
        done = [a for a in actions if a not in live]
        if done:
            raise ValueError(f"step: agent {done[0]!r} is done (it left the episode); "
                             f"act only for env.agents")
        missing = [a for a in live if a not in actions]
        if missing:
            raise ValueError(f"step: no action for agent {missing[0]!r} (one action for each "
                             f"of env.agents)")
        groups = {}  # actions checked in their own precision, one pass per dtype
        for a in live:
            act = np.asarray(actions[a])
            if act.dtype.kind not in "iuf":  # before its shape: 'go' has shape ()
                raise ValueError(f"the action for agent {a!r} must be real numbers, got "
                                 f"dtype {act.dtype}")
            if act.shape != (core.A,):
                raise ValueError(f"the action for agent {a!r} has shape {act.shape}, the "
                                 f"action space's is ({core.A},) ({self.joint_names})")
            groups.setdefault(act.dtype, []).append((a, act))
        batch = np.zeros((core.N, core.A))
        for group in groups.values():
            names = [a for a, _ in group]
            batch[[index[a] for a in names]] = _check_actions(
                core, np.stack([act for _, act in group]), lambda m: f"agent {names[m]!r}",
                self._clip)
        core.set_actions([0], batch[None])
        core.step_all(np.ones(1, dtype=bool))
        core.observe()
        core.score(np.ones(1, dtype=bool))
        obs = core.obs[0]
        rewards, term, trunc = core.rewards[0], core.terminated[0], core.truncated[0]
        result = (
            {a: obs[index[a]].copy() for a in live},
            {a: float(rewards[index[a]]) for a in live},
            {a: bool(term[index[a]]) for a in live},
            {a: bool(trunc[index[a]]) for a in live},
            {a: {} for a in live},
        )
        self.agents = [a for a in live if core.active[0][index[a]]]
        return result

    def render(self):
        """Nothing to show in a window: returns None (swarmsim's recordings, snapshots and
        viewer show runs; see README.md)."""
        return None

    def state(self):
        """Every possible agent's observation, concatenated (N x D values): a global view
        for centralised training."""
        if self._core.closed:
            raise RuntimeError("the environment is closed")
        return self._core.obs[0].reshape(-1).copy()

    @_one_thread_at_a_time
    def close(self):
        """Closes the world (the environment cannot be used after)."""
        self._core.close()
        self.agents = []


# --- The batched form -----------------------------------------------------------------------

try:  # Gymnasium's VectorEnv and autoreset modes when Gymnasium is installed
    from gymnasium.vector import VectorEnv as _VectorBase
    try:
        from gymnasium.vector import AutoresetMode as _AutoresetMode
        NEXT_STEP = _AutoresetMode.NEXT_STEP
    except ImportError:
        NEXT_STEP = "NextStep"
except ImportError:
    _VectorBase = None
    NEXT_STEP = "NextStep"


def _seed_np_random(env, seed):
    """env.np_random from `seed` (None: drawn at random), as Gymnasium's seeding.np_random
    makes it; also with Gymnasium's own VectorEnv, whose np_random reads these attributes."""
    if seed is None:
        seed = int(np.random.SeedSequence().entropy)
    env._np_random, env._np_random_seed = np.random.default_rng(seed), seed


class _VectorFallback:
    """What Gymnasium's VectorEnv gives its subclasses, for when it is not installed: `spec`
    (None: not made by gymnasium.make_vec), `unwrapped`, `np_random` (a numpy Generator,
    seeded at random on first use, or by ``reset(seed=int)``) and `np_random_seed` (-1 once
    a Generator is set)."""

    spec = None
    _np_random = None
    _np_random_seed = None

    @property
    def unwrapped(self):
        """The environment itself (no wrapper around it)."""
        return self

    @property
    def np_random(self):
        """The environment's own numpy Generator (not the worlds': they have their seeds)."""
        if self._np_random is None:
            _seed_np_random(self, None)
        return self._np_random

    @np_random.setter
    def np_random(self, value):
        self._np_random, self._np_random_seed = value, -1

    @property
    def np_random_seed(self):
        """The seed `np_random` was made from (-1: a Generator set, or drawn at random)."""
        if self._np_random is None:
            _seed_np_random(self, None)
        return self._np_random_seed


    def get_wrapper_attr(self, name):
        """getattr(self, name): no wrapper to look through."""
        return getattr(self, name)

    def set_wrapper_attr(self, name, value):
        """setattr(self, name, value)."""
        setattr(self, name, value)


if _VectorBase is None:
    _VectorBase = _VectorFallback


class VectorEnv(_AgentsOfAModel, _VectorBase):
    """K copies of one world (K "environments"), each with the same N agents, as arrays:
    observations (K, N, D), actions (K, N, A), rewards, terminations and truncations (K, N).
    Gymnasium's vector conventions: ``reset(seed=None, options=None) -> (observations,
    infos)``, ``step(actions) -> (observations, rewards, terminations, truncations, infos)``,
    ``single_observation_space`` (N, D), ``observation_space`` (K, N, D) and the same for
    actions, ``num_envs``; ``metadata["autoreset_mode"]`` is next-step (Gymnasium 1.x's
    default): the step after an environment's episode ended (every agent terminated or
    truncated) resets it, ignores its actions, and returns its first observations with
    rewards 0 and terminations and truncations False.

    An agent that terminated before its environment's episode ends stays in the arrays: its
    termination stays True, its actions are ignored (its joints get target 0), its rewards
    are 0 and its observations go on being read. ``infos["active"]`` (K, N) says which
    agents act in the next step.

    ``VectorEnv(world, num_envs, ..., seed=None, threads=1, ...)``: the declarations as
    ParallelEnv's; ``threads`` per world. The K worlds are stepped together by
    ``swarmsim.step_worlds`` where the module has it (``has_parallel_step()``), else one
    after the other.
    """

    metadata = {"autoreset_mode": NEXT_STEP, "render_modes": []}
    render_mode = None

    def __init__(self, world, num_envs, observations=None, actions=None, reward=None,
                 terminate=None, max_steps="world", model=None, seed=None, set=None,
                 threads=1, step_threads=0, clip_actions=False, keep_scripts=True,
                 world_options=None):
        spec = _spec(world, observations, actions, reward, terminate, max_steps, model, seed,
                     set, threads, world_options, keep_scripts, step_threads)
        self._core = Core(spec, num_envs)
        core = self._core
        self._clip = _flag(clip_actions, "clip_actions")
        self.num_envs = core.K
        self.possible_agents = list(core.agents)
        self.agents = list(core.agents)
        self.num_agents = core.N
        K, N, D, A = core.K, core.N, core.D, core.A
        obs_low = np.broadcast_to(core.obs_low, (N, D))
        obs_high = np.broadcast_to(core.obs_high, (N, D))
        act_low = np.broadcast_to(core.actions.low, (N, A))
        act_high = np.broadcast_to(core.actions.high, (N, A))
        self.single_observation_space = spaces.Box(obs_low, obs_high, (N, D), np.float64)
        self.single_action_space = spaces.Box(act_low, act_high, (N, A), np.float64)
        self.observation_space = spaces.Box(np.broadcast_to(obs_low, (K, N, D)),
                                            np.broadcast_to(obs_high, (K, N, D)), (K, N, D),
                                            np.float64)
        self.action_space = spaces.Box(np.broadcast_to(act_low, (K, N, A)),
                                       np.broadcast_to(act_high, (K, N, A)), (K, N, A),
                                       np.float64)
        self.closed = False
        self._ended = np.zeros(K, dtype=bool)  # reset at the next step
        self._started = False

    @property
    def worlds(self):
        """The K swarmsim.World objects (read any array from them; do not step them)."""
        if self._core.closed:
            raise RuntimeError("the environment is closed")
        return [s.world for s in self._core.slots]

    @property
    def max_steps(self):
        return self._core.max_steps

    @property
    def episode_steps(self):
        """(K,) each environment's step count in its episode."""
        return self._core.episode_steps.copy()

    @property
    def seeds(self):
        """Each environment's current episode's seed."""
        return [s.seed for s in self._core.slots]

    def _infos(self):
        return {"active": self._core.active.copy(), "_active": np.ones(self.num_envs, bool)}

    @_one_thread_at_a_time
    def reset(self, seed=None, options=None):
        """Resets every environment (or those of ``options={"reset_mask": (K,) bools}``).
        seed: None (each environment's next seed: the world file's + k the first time), an
        int s (environment k gets s + k) or a list of K seeds. ``options={"poses": (K, N, 3
        or 7)}`` places the robots (World.set_poses, in builds that have it). Returns
        (observations, infos)."""
        core = self._core
        if core.closed:
            raise RuntimeError("the environment is closed")
        K = core.K
        mask = np.ones(K, dtype=bool)
        options = _options(options)
        if "reset_mask" in options:
            mask = np.asarray(options.pop("reset_mask"))
            if mask.dtype != bool or mask.shape != (K,):
                raise ValueError(f"reset: options['reset_mask'] must be ({K},) bools")
            if not self._started and not mask.all():
                raise ValueError("reset: the first reset resets every environment")
        poses = options.pop("poses", None)
        if options:
            raise ValueError(f"reset: unknown options {sorted(options)} (known: 'reset_mask', "
                             f"'poses')")
        if seed is None:
            seeds = [None] * K
        elif np.ndim(seed) == 0:
            seeds = [whole_number(seed, "reset: seed") + k for k in range(K)]
            # Checked before any environment resets (s + k past 2**64 - 1 left env 0
            # reset and the others not, naming a seed nobody passed).
            if seeds[-1] > 2**64 - 1:
                raise ValueError(f"reset: seed {seeds[0]} gives environment {K - 1} the seed "
                                 f"{seeds[-1]}, past 2**64 - 1: pass a seed up to "
                                 f"{2**64 - K}, or a list of {K} seeds")
        else:
            seeds = list(seed)
            if len(seeds) != K:
                raise ValueError(f"reset: {len(seeds)} seeds for {K} environments")
            seeds = [None if x is None else whole_number(x, f"reset: seed[{k}]")
                     for k, x in enumerate(seeds)]
        ks = [k for k in range(K) if mask[k]]
        if poses is not None:  # every environment's checked before any resets
            if isinstance(poses, (str, bytes)) or np.ndim(poses) != 3 or len(poses) != K:
                raise ValueError(f"reset: options['poses'] must be (K={K}, N, 3 or 7), got "
                                 f"shape {np.shape(poses)}")
            poses = [core.checked_poses(poses[k]) for k in range(K)]
        if seed is not None and np.ndim(seed) == 0:
            _seed_np_random(self, seeds[0])  # as Gymnasium's VectorEnv.reset does
        for k in ks:
            core.reset_world(k, seeds[k], None if poses is None else poses[k])
        self._step_some(ks)
        core.observe()
        for k in ks:
            core.active[k] = core.present[k]
        self._ended[mask] = False
        self._started = True
        return core.obs.copy(), self._infos()

    def _step_some(self, ks):
        core = self._core
        if len(ks) == core.K:
            core.step_all()
            return
        # Only some worlds: step those (the others keep their state).
        for slot in core.slots:
            slot.called = False
        core.step_list([core.slots[k].world for k in ks])
        for k in ks:
            slot = core.slots[k]
            if not slot.called and slot.indices:
                core._remap(slot, [], [])

    @_one_thread_at_a_time
    def step(self, actions):
        """One step of every environment: actions (K, N, A) (rows of inactive agents and of
        environments being reset are ignored). Returns (observations (K, N, D), rewards
        (K, N), terminations (K, N), truncations (K, N), infos)."""
        core = self._core
        if core.closed:
            raise RuntimeError("the environment is closed")
        if not self._started:
            raise RuntimeError("call reset() before step()")
        acts = np.asarray(actions)
        if acts.shape != (core.K, core.N, core.A):
            raise ValueError(f"actions have shape {acts.shape}, expected "
                             f"({core.K}, {core.N}, {core.A}): environments x agents x "
                             f"{self.joint_names}")
        resetting = self._ended.copy()
        counts = core.active & ~resetting[:, None]
        checked = np.zeros((core.K, core.N, core.A))
        if counts.any():
            where = np.argwhere(counts)
            agents = self.possible_agents
            checked[counts] = _check_actions(
                core, acts[counts],
                lambda m: f"environment {where[m][0]}, agent {agents[where[m][1]]!r}",
                self._clip)
        for k in np.flatnonzero(resetting):
            core.reset_world(int(k))
        going = np.flatnonzero(~resetting)
        core.set_actions(going, checked[going])
        core.step_all(~resetting)
        core.observe()
        core.active[resetting] = core.present[resetting]
        core.score(~resetting)
        self._ended = ~core.active.any(axis=1)
        return (core.obs.copy(), core.rewards.copy(), core.terminated.copy(),
                core.truncated.copy(), self._infos())

    def render(self):
        """Returns None (see ParallelEnv.render)."""
        return None

    @_one_thread_at_a_time
    def close(self, **kwargs):
        """Closes the K worlds."""
        if not self.closed:
            self._core.close()
            self.closed = True
