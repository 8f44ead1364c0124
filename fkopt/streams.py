"""Per-run random streams.

Every run k of an experiment with seed s draws from its own generator
``PCG64(SeedSequence(s, spawn_key=(k,)))`` -- exactly the k-th child of
``SeedSequence(s).spawn(n)`` -- so run k produces the same numbers whether it runs alone, in a
batch of 30 or on another worker. Nothing in fkopt touches numpy's global RNG.

Algorithms only ever draw *uniforms* through :class:`RunStreams`; integers and other
distributions are derived from them (``floor(u * n)``). Uniforms are drawn per run in large
chunks and buffered: PCG64's ``random()`` consumes exactly one 64-bit output per double, so the
sequence a run sees does not depend on the chunk size or on how many other runs share the
batch. This keeps the hot loop free of per-run Python calls except once per chunk.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

CHUNK = 4096


def run_seed_sequence(seed: int, run: int) -> np.random.SeedSequence:
    """The seed sequence of run ``run`` of an experiment seeded with ``seed``."""
    return np.random.SeedSequence(seed, spawn_key=(run,))


class RunStreams:
    """One independent uniform stream per run, served as arrays shaped (runs, ...)."""

    def __init__(self, seed: int, run_ids: Sequence[int]):
        self.seed = int(seed)
        self.run_ids = [int(k) for k in run_ids]
        self._generators = [np.random.Generator(np.random.PCG64(run_seed_sequence(self.seed, k)))
                            for k in self.run_ids]
        self._buffer = np.empty((len(self.run_ids), 0))
        self._pos = 0

    @property
    def runs(self) -> int:
        return len(self.run_ids)

    def uniform(self, *shape: int) -> np.ndarray:
        """Uniforms in [0, 1) shaped (runs, *shape); each run's values come from its own stream."""
        n = int(np.prod(shape)) if shape else 1
        if self._pos + n > self._buffer.shape[1]:
            fresh = max(n, CHUNK)
            new = np.stack([g.random(fresh) for g in self._generators]) if self._generators \
                else np.empty((0, fresh))
            self._buffer = np.concatenate([self._buffer[:, self._pos:], new], axis=1)
            self._pos = 0
        out = self._buffer[:, self._pos:self._pos + n]
        self._pos += n
        return out.reshape((self.runs, *shape))

    def integers(self, high: int, *shape: int) -> np.ndarray:
        """Integers in [0, high) shaped (runs, *shape)."""
        return np.minimum((self.uniform(*shape) * high).astype(np.intp), high - 1)

    def index_other_than(self, n: int, exclude: np.ndarray) -> np.ndarray:
        """Uniform indices in [0, n) shaped like ``exclude`` (runs, ...), never equal to ``exclude``.

        Used for ABC's random neighbour k != i.
        """
        k = self.integers(n - 1, *exclude.shape[1:])
        return k + (k >= exclude)
