"""A vectorised, learning-style environment over one swarmsim world (no learning library).

Every foot-bot of worlds/diffusion.yaml is one agent. Each step the caller gives one
action per robot (left and right wheel speeds in m/s, clipped to +-0.1) and gets back:

  observations  (N, 24 + 2) the 24 proximity readings as 1 - d/range (0: nothing seen)
                and the robot's heading as (cos, sin)
  rewards       (N,)  distance covered this step, minus 0.1 for each sensor closer than 3 cm
  dones         (N,)  True for every robot when the episode ends (`episode_steps`)

reset(seed) rebuilds the world with that seed, so an episode is reproducible:
same seed and actions, same observations, whatever the thread count.

    PYTHONPATH=build/python /usr/bin/python3 scripts/diffusion_env.py --robots 100
"""

import argparse
import pathlib

import numpy as np

import swarmsim

ROOT = pathlib.Path(__file__).resolve().parent.parent
RANGE = 0.1  # m, the foot-bot's proximity range


class DiffusionEnv:
    def __init__(self, robots=100, episode_steps=200, threads=0,
                 world=ROOT / "worlds" / "diffusion.yaml"):
        self.robots, self.episode_steps, self.threads, self.world_file = (
            robots, episode_steps, threads, str(world))
        self.world = None
        self.actions = None  # set by step(), applied by the controller below

    def _controller(self, robots):
        left, right = self.actions[:, 0], self.actions[:, 1]
        radius = robots.param("wheel_radius")
        return {"leftMotor": left / radius, "rightMotor": right / radius}

    def _observe(self):
        d = self.world.proximity("footbot")
        seen = np.where(np.isfinite(d), 1 - d / RANGE, 0.0)
        # The heading's cosine and sine straight from the quaternion (the body's x axis
        # in the plane), not np.cos/np.sin of the yaw: numpy's SIMD sin/cos may round a
        # value differently depending on where the array lies in memory, which would
        # make equal runs give observations an ulp apart.
        q = self.world.poses("footbot", columns=7)
        w, x, y, z = q[:, 3], q[:, 4], q[:, 5], q[:, 6]
        cos_yaw = 1 - 2 * (y * y + z * z)
        sin_yaw = 2 * (x * y + w * z)
        return np.hstack([seen, cos_yaw[:, None], sin_yaw[:, None]])

    def reset(self, seed):
        if self.world is not None:
            self.world.close()
        self.world = swarmsim.World(self.world_file, seed=seed, threads=self.threads,
                                    set={"robots": self.robots},
                                    controllers={"footbot": self._controller})
        self.actions = np.zeros((self.robots, 2))
        self.world.step()  # sensors read once
        self._xy = self.world.poses("footbot")[:, :2].copy()
        return self._observe()

    def step(self, actions):
        actions = np.asarray(actions, dtype=np.float64)
        if actions.shape != (self.robots, 2):
            raise ValueError(f"actions must have shape ({self.robots}, 2), got {actions.shape}")
        self.actions = np.clip(actions, -0.1, 0.1)
        self.world.step()
        xy = self.world.poses("footbot")[:, :2]
        moved = np.linalg.norm(xy - self._xy, axis=1)
        self._xy = xy.copy()
        obs = self._observe()
        close = (obs[:, :24] > 1 - 0.03 / RANGE).sum(axis=1)
        rewards = moved - 0.1 * close
        done = self.world.steps > self.episode_steps
        return obs, rewards, np.full(self.robots, done)

    def close(self):
        if self.world is not None:
            self.world.close()
            self.world = None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=100)
    parser.add_argument("--steps", type=int, default=100)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    env = DiffusionEnv(robots=args.robots, episode_steps=args.steps)
    obs = env.reset(args.seed)
    rng = np.random.default_rng(args.seed)
    total = np.zeros(args.robots)
    dones = np.zeros(args.robots, dtype=bool)
    while not dones.all():
        # A hand-written policy: go straight, turn away from what the front sensors see.
        front = obs[:, [0, 1, 23]].sum(axis=1)
        actions = np.where(front[:, None] > 0.2, [0.05, -0.05], [0.05, 0.05])
        actions = actions + rng.normal(0, 0.005, size=actions.shape)
        obs, rewards, dones = env.step(actions)
        total += rewards
    print(f"{args.robots} robots, {args.steps} steps: mean return {total.mean():.4f} m")
    env.close()


if __name__ == "__main__":
    main()
