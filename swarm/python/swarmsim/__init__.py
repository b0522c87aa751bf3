"""swarmsim from Python: load a world file, step it, read and drive the swarm with numpy.

    import swarmsim
    w = swarmsim.World("worlds/diffusion.yaml", seed=7, set={"robots": 200}, threads=2)
    w.step(100)
    xy_yaw = w.poses()          # (N, 3) for planar worlds, (N, 7) x y z qw qx qy qz in 3D
    print(w.time, w.state_hash(), w.metrics)

A models entry may name a Python controller (``python_controller: FILE.py:function``)
or one may be given here (``World(..., controllers={"footbot": fn})``): it is called
once per step with a :class:`Robots` holding the arrays of all the model's robots and
returns ``{joint name: array of one target per robot}``. See README.md, "Python".

Many worlds at once: ``swarmsim.step_worlds([w1, w2, ...], n, threads=2)`` steps them in
parallel, each ending exactly as stepping it alone would.

Between steps Python may write state: ``set_poses``, ``set_velocities``,
``set_joint_positions``, ``set_joint_velocities``, ``set_joint_targets``, ``set_param``,
``set_range_and_bearing_data``, ``send_ir_messages``. Every sensor reads as an array:
proximity, ground, light, range-and-bearing, IR messages, vision images and depth, blob
cameras, force sensors, distance and collision objects.

``w.snapshot()`` -> bytes and ``w.restore(bytes)`` save and restore the state (restore + k
steps gives the hash of the uninterrupted run), ``w.reset(seed=None)`` goes back in place to
a fresh load with that seed, and ``pickle`` goes through them; worlds whose robots run Lua
scripts are refused (README.md, "Python": snapshots).

Errors: a world that does not load raises ValueError with the message the command
line prints (file:line:column); a script or controller error while stepping raises
RuntimeError (with the controller's traceback) and the world cannot be stepped again.
Wrong shapes, names and values raise ValueError, non-numbers TypeError. A World is
used by one thread at a time (another thread's call waits); a controller may read its
world but not step, close or write it (RuntimeError). A ``Robots`` object kept after
its step raises RuntimeError. Every array is a copy (pass ``out=`` to reuse one).
"""

import sys

try:
    import numpy  # noqa: F401  (the arrays' type; Debian's python3-numpy)
    from ._swarmsim import Robots, World, step_worlds
except ImportError as e:
    raise ImportError(
        f"swarmsim is built for Debian's Python, /usr/bin/python3 (with python3-numpy); "
        f"this is {sys.executable}: run your script with /usr/bin/python3 ({e})") from e

__all__ = ["World", "Robots", "step_worlds"]
