"""Spaces for swarmsim.env: ``gymnasium.spaces.Box`` when gymnasium is importable, else
:class:`Box` below, which follows the same documented interface.

``swarmsim.spaces.Box`` is the class the environments build their spaces with: gymnasium's
Box if ``import gymnasium`` works (so that a learning library sees the type it expects),
else the fallback, whose members a training loop uses the same way:

    space.shape, space.dtype, space.low, space.high   # arrays of `shape`
    space.sample()        # a random element (from space.np_random)
    space.contains(x)     # x in space: dtype castable, same shape, low <= x <= high
    space.seed(seed)      # seeds space.np_random (numpy's Generator); returns [seed]
    space.is_bounded("both" | "below" | "above")

``swarmsim.spaces.GYMNASIUM`` says which one is in use. Neither gymnasium nor PettingZoo is a
dependency of swarmsim.
"""

import numpy as np

__all__ = ["Box", "FallbackBox", "GYMNASIUM"]


class FallbackBox:
    """A box in R^n, as ``gymnasium.spaces.Box``: each coordinate lies in [low[i], high[i]].

    ``Box(low, high, shape=None, dtype=np.float32, seed=None)``: ``low`` and ``high`` are
    numbers (broadcast to ``shape``) or arrays (``shape`` is theirs); ``-inf``/``inf`` leave a
    side unbounded. ``sample()`` draws uniformly on bounded coordinates, from an exponential
    on half-bounded ones and from a normal distribution on unbounded ones (as gymnasium does).
    """

    def __init__(self, low, high, shape=None, dtype=np.float32, seed=None):
        self.dtype = np.dtype(dtype)
        if shape is None:
            for bound in (low, high):
                if np.ndim(bound) > 0:
                    shape = np.shape(bound)
                    break
            else:
                shape = (1,)
        self._shape = tuple(int(s) for s in shape)
        self.low = np.broadcast_to(np.asarray(low, dtype=self.dtype), self._shape).copy()
        self.high = np.broadcast_to(np.asarray(high, dtype=self.dtype), self._shape).copy()
        if np.any(self.low > self.high):
            raise ValueError(f"Box: low must be <= high everywhere, got low={low}, high={high}")
        self._np_random = None
        if seed is not None:
            self.seed(seed)

    @property
    def shape(self):
        """The shape of an element (a tuple)."""
        return self._shape

    @property
    def np_random(self):
        """The space's numpy Generator (seeded from entropy on first use, or by seed())."""
        if self._np_random is None:
            self.seed()
        return self._np_random

    def seed(self, seed=None):
        """Seeds the sampler; returns [seed]."""
        self._np_random = np.random.default_rng(seed)
        return [seed]

    def is_bounded(self, manner="both"):
        """Whether every coordinate is bounded below, above or on both sides."""
        below = bool(np.all(np.isfinite(self.low)))
        above = bool(np.all(np.isfinite(self.high)))
        if manner == "both":
            return below and above
        if manner == "below":
            return below
        if manner == "above":
            return above
        raise ValueError(f"manner is 'both', 'below' or 'above', got {manner!r}")

    def sample(self, mask=None):
        """A random element of the space."""
        if mask is not None:
            raise ValueError("Box.sample: a Box takes no mask")
        rng = self.np_random
        low = self.low.astype(np.float64)
        high = self.high.astype(np.float64)
        out = np.empty(self._shape, dtype=np.float64)
        bounded = np.isfinite(low) & np.isfinite(high)
        below = np.isfinite(low) & ~np.isfinite(high)
        above = ~np.isfinite(low) & np.isfinite(high)
        free = ~np.isfinite(low) & ~np.isfinite(high)
        out[bounded] = rng.uniform(low[bounded], high[bounded])
        out[below] = low[below] + rng.exponential(size=int(below.sum()))
        out[above] = high[above] - rng.exponential(size=int(above.sum()))
        out[free] = rng.normal(size=int(free.sum()))
        out = np.clip(out, low, high)  # a float32 rounding past a bound
        return out.astype(self.dtype)

    def contains(self, x):
        """True if x is an element: castable to dtype, of this shape, within the bounds."""
        if not isinstance(x, np.ndarray):
            try:
                x = np.asarray(x, dtype=self.dtype)
            except (ValueError, TypeError):
                return False
        return bool(np.can_cast(x.dtype, self.dtype) and x.shape == self._shape
                    and np.all(x >= self.low) and np.all(x <= self.high))

    def __contains__(self, x):
        return self.contains(x)

    def __eq__(self, other):
        return (isinstance(other, FallbackBox) and self._shape == other._shape
                and self.dtype == other.dtype and np.array_equal(self.low, other.low)
                and np.array_equal(self.high, other.high))

    def __repr__(self):
        def bound(b):
            flat = np.unique(b)
            return str(flat[0]) if flat.size == 1 else str(b)
        return f"Box({bound(self.low)}, {bound(self.high)}, {self._shape}, {self.dtype})"


try:  # the space a learning library expects, when it is installed
    from gymnasium.spaces import Box  # noqa: F401
    GYMNASIUM = True
except ImportError:
    Box = FallbackBox
    GYMNASIUM = False
