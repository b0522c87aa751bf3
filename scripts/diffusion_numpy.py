"""Foot-bot diffusion as one vectorised numpy controller for the whole swarm.

The same rule as scripts/diffusion.lua (after ARGoS's diffusion example): sum the
24 proximity readings as vectors pointing at what each sensor sees; drive straight
if nothing is ahead, else turn away. One call per step for all robots:

    worlds/python/diffusion_numpy.yaml:   python_controller: ../../scripts/diffusion_numpy.py
    PYTHONPATH=build/python /usr/bin/python3 -m swarmsim run worlds/python/diffusion_numpy.yaml
"""

import numpy as np

RANGE = 0.1  # m, the proximity sensors' range (worlds/models/footbot.yaml)

_constants = {}


def _setup(robots):
    """Per-robot constants, read once (parameters do not change during a run)."""
    s = len(robots.sensor_names)
    angles = 2 * np.pi * np.arange(s) / s
    return {
        "count": robots.count,
        "cos": np.cos(angles),
        "sin": np.sin(angles),
        "wheel": robots.param("wheel_speed") / robots.param("wheel_radius"),  # rad/s
        "straight": np.radians(robots.param("go_straight_angle_deg")),
        "delta": robots.param("delta"),
    }


def control(robots):
    c = _constants.get("footbot")
    if c is None or c["count"] != robots.count:
        c = _constants["footbot"] = _setup(robots)
    d = robots.proximity  # (N, 24) metres, inf where a sensor sees nothing
    value = np.where(np.isfinite(d), 1 - d / RANGE, 0.0)
    # Summed sensor by sensor, in the Lua script's order: the same sums to the last bit,
    # so this controller moves the robots exactly as scripts/diffusion.lua does.
    x = np.zeros(robots.count)
    y = np.zeros(robots.count)
    for i in range(value.shape[1]):
        x += value[:, i] * c["cos"][i]
        y += value[:, i] * c["sin"][i]
    angle = np.arctan2(y, x)
    straight_on = (np.abs(angle) <= c["straight"]) & (np.sqrt(x * x + y * y) < c["delta"])
    left = np.where(straight_on | (angle > 0), c["wheel"], 0.0)
    right = np.where(straight_on | (angle <= 0), c["wheel"], 0.0)
    return {"leftMotor": left, "rightMotor": right}
