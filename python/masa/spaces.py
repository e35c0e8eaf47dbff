"""Observation and action spaces: Gymnasium's Box when Gymnasium is installed, else a small Box
with the same attributes (shape, dtype, low, high, sample, contains). sample() draws from the
space's own generator, seeded (0 unless seed() says otherwise: the same seed, the same samples)."""
import numpy as np

try:
    from gymnasium.spaces import Box  # noqa: F401
except ImportError:

    class Box:
        """A box of float arrays, low <= x <= high element-wise (Gymnasium's Box, in small)."""

        def __init__(self, low, high, shape=None, dtype=np.float32, seed=0):
            self.dtype = np.dtype(dtype)
            shape = tuple(shape) if shape is not None else np.shape(low)
            self.shape = shape
            self.low = np.broadcast_to(np.asarray(low, dtype=self.dtype), shape).copy()
            self.high = np.broadcast_to(np.asarray(high, dtype=self.dtype), shape).copy()
            self.np_random = np.random.default_rng(seed)

        def seed(self, seed=0):
            self.np_random = np.random.default_rng(seed)
            return [seed]

        def sample(self):
            # Unbounded dimensions draw from a standard normal, as Gymnasium's Box does.
            bounded = np.isfinite(self.low) & np.isfinite(self.high)
            x = self.np_random.standard_normal(self.shape)
            u = self.np_random.uniform(np.where(bounded, self.low, 0), np.where(bounded, self.high, 1), self.shape)
            return np.where(bounded, u, x).astype(self.dtype)

        def contains(self, x):
            x = np.asarray(x)
            return x.shape == self.shape and bool(np.all(x >= self.low) and np.all(x <= self.high))

        def __repr__(self):
            return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"

        def __eq__(self, other):
            return (isinstance(other, Box) and self.shape == other.shape and self.dtype == other.dtype
                    and np.array_equal(self.low, other.low) and np.array_equal(self.high, other.high))


def batch(space, n):
    """The space of n stacked samples of `space`."""
    return Box(np.broadcast_to(space.low, (n,) + space.shape), np.broadcast_to(space.high, (n,) + space.shape),
               (n,) + space.shape, space.dtype)
