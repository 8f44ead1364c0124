"""Per-run random streams.

Every run k of an experiment with seed s draws from its own generator
``PCG64(SeedSequence(s, spawn_key=(k,)))`` -- exactly the k-th child of
``SeedSequence(s).spawn(n)`` -- so run k produces the same numbers whether it runs alone, in a
batch of 30 or on another worker. Nothing in fkopt touches numpy's global RNG.

Several targets (cases) solved in one batch: each case has its own integer seed (given per
case, or derived from one seed by :func:`case_seed`), and run k of case c draws from
``run_seed_sequence(seed_c, k)``. A row of a batch is therefore identified by (seed, run id)
alone, and :class:`RunStreams` takes one seed per row.

Algorithms only ever draw *uniforms* through :class:`RunStreams`; integers and other
distributions are derived from them (``floor(u * n)``). Uniforms are drawn per run in large
chunks and buffered: PCG64's ``random()`` consumes exactly one 64-bit output per double, so the
sequence a run sees does not depend on the chunk size or on how many other runs share the
batch. This keeps the hot loop free of per-run Python calls except once per chunk.

Consumption order. Each call ``uniform(*shape)`` takes the next ``prod(shape)`` values of every
run's sequence, in C order of ``shape``; so one call ``uniform(3, n)`` hands out exactly the
numbers that three calls ``uniform(n)`` would, in the same order. What an algorithm draws,
and in which order, is documented in its module (see :mod:`fkopt.algorithms.abc`).

Speed. ``uniform`` returns a view into the buffer (no copy, no per-run call): a slice and a
reshape, about a microsecond whatever the number of runs. Each value is handed out once, so an
algorithm may overwrite the view it got without affecting any other draw.

Refills. On the compiled numerics path (:mod:`fkopt.numerics.path`) one compiled call refills
every run (:func:`fkopt.numerics.compiled.fill_uniforms`): numpy's PCG64 step and ``next_double``
on the runs' 128-bit states held in one array, so the same bits as ``Generator.random`` (tested);
the states go back into the generators when the numpy refill takes over. It runs with many runs
(more than ``BUFFER_VALUES // CHUNK`` = 128; numba is imported if need be), where one Python call
``Generator.random(out=...)`` per run and refill and the generators' scattered states cost half
the refill, and with fewer runs once numba is loaded anyway (a compiled swarm's first iteration
loads it; never imported for them). With no call per run the buffer is smaller
(:data:`COMPILED_BUFFER_VALUES`) and stays in cache (what it buys: docs/performance.md, the
swarms row). ``FKOPT_NUMERICS=numpy`` keeps the per-run numpy calls.
"""
from __future__ import annotations

import sys
from collections.abc import Sequence
from math import prod

import numpy as np

from fkopt.numerics import path as numerics_path

#: Uniforms buffered per run and refill (any value gives the same numbers; this one is fast).
CHUNK = 8192
#: Upper bound on the values buffered over all runs of a batch (8 MB): with many rows each run
#: refills in smaller pieces (at least :data:`MIN_REFILL`). Again, the numbers do not depend on it.
BUFFER_VALUES = 1 << 20
MIN_REFILL = 256
#: The same bound for the compiled refill (512 kB), which has no per-run cost: a buffer that stays
#: in a core's cache beside a swarm's state (an 8 MB one did not; docs/performance.md).
COMPILED_BUFFER_VALUES = 1 << 16
COMPILED_MIN_REFILL = 32


def run_seed_sequence(seed: int, run: int) -> np.random.SeedSequence:
    """The seed sequence of run ``run`` of an experiment seeded with ``seed``."""
    return np.random.SeedSequence(seed, spawn_key=(run,))


def case_seed(seed: int, case: int) -> int:
    """The integer seed of case ``case`` when a batch of cases is given one seed ``seed``:
    the first 32-bit word of ``SeedSequence(seed, spawn_key=(case,))``'s state, i.e. of the
    case-th child of ``SeedSequence(seed)``. Solving case c alone with this seed reproduces it."""
    return int(np.random.SeedSequence(int(seed), spawn_key=(int(case),)).generate_state(1)[0])


class RunStreams:
    """One independent uniform stream per run, served as arrays shaped (runs, ...).

    ``seed`` is one integer for every row, or one per row (rows of several cases in a batch).
    """

    def __init__(self, seed: int | Sequence[int], run_ids: Sequence[int]):
        self.run_ids = [int(k) for k in run_ids]
        if np.ndim(seed) == 0:
            self.seed = int(seed)
            self.seeds = [self.seed] * len(self.run_ids)
        else:
            self.seeds = [int(s) for s in seed]
            if len(self.seeds) != len(self.run_ids):
                raise ValueError(f"{len(self.seeds)} seeds for {len(self.run_ids)} runs")
            self.seed = self.seeds[0] if len(set(self.seeds)) == 1 else None
        self._generators = [np.random.Generator(np.random.PCG64(run_seed_sequence(s, k)))
                            for s, k in zip(self.seeds, self.run_ids)]
        self._runs = len(self.run_ids)
        self._refill_size = max(MIN_REFILL, min(CHUNK, BUFFER_VALUES // max(self._runs, 1)))
        self._buffer = np.empty((self._runs, 0))
        self._pos = 0
        self._size = 0
        self._fill = None              # (kernel, PCG64 states, kernels module) while the compiled refill runs
        self._stores: list[np.ndarray] = []   # the compiled refill's buffers (see _free_store)

    @property
    def runs(self) -> int:
        return self._runs

    def _refill(self, n: int) -> None:
        """Keep the unread tail and append at least ``n`` fresh values per run."""
        tail = self._size - self._pos
        fill = self._compiled_fill()
        if fill is None and self._fill is not None:   # the compiled path was left: numpy's calls continue
            self._sync_generators()
        fresh = max(n, self._refill_size if fill is None else
                    max(COMPILED_MIN_REFILL, min(CHUNK, COMPILED_BUFFER_VALUES // self._runs)))
        if fill is None:
            buf = np.empty((self._runs, tail + fresh))
            buf[:, :tail] = self._buffer[:, self._pos:]
            for row, g in zip(buf, self._generators):
                g.random(out=row[tail:])
        else:
            need = self._runs * (tail + fresh)
            buf = self._free_store(need, 2 * self._runs * fresh)[:need].reshape(self._runs, tail + fresh)
            buf[:, :tail] = self._buffer[:, self._pos:]
            fill[0](buf, tail, fill[1])
        self._buffer, self._pos, self._size = buf, 0, tail + fresh

    def _free_store(self, need: int, size: int) -> np.ndarray:
        """A flat array of at least ``need`` values that no handed-out view (nor the current buffer)
        points into, for the compiled refill's next buffer: one of :attr:`_stores` when its reference
        count says nothing else holds it (every view of a view keeps the owning array as its
        ``base``), else a new one of ``size`` values, kept while fewer than four are. Why: a fresh
        ``np.empty`` per refill is fresh pages from the OS on first touch, a cost beside the fill
        itself. A view an algorithm keeps is never overwritten."""
        for store in self._stores:
            # references: the list, this loop's variable, getrefcount's argument -- nothing else
            if store.size >= need and sys.getrefcount(store) <= 3:
                return store
        store = np.empty(max(need, size))
        if len(self._stores) < 4:
            self._stores.append(store)
        return store

    def _compiled_fill(self):
        """(kernel, PCG64 states) of the compiled refill, or None for numpy's per-run calls: when
        the compiled path is on (asked on every refill: ``FKOPT_NUMERICS`` may change between
        calls) and either refills are shorter than :data:`CHUNK` (many runs; numba is imported if
        need be) or numba is loaded already (a compiled swarm's first iteration loads it). The
        states are the generators' own, copied into one array on first use; from then on the array
        is the streams' state (:meth:`_sync_generators` writes it back)."""
        kernels = numerics_path.compiled() if self._refill_size < CHUNK else numerics_path.loaded()
        if kernels is None:
            return None
        if self._fill is None:
            self._fill = (kernels.fill_uniforms, kernels.pcg64_states(self._generators), kernels)
        return self._fill

    def _sync_generators(self) -> None:
        """The compiled refill's states back into the generators (numpy draws continue the
        streams), and the compiled refill forgotten (it takes them up again when next used)."""
        if self._fill is not None:
            self._fill[2].store_pcg64_states(self._generators, self._fill[1])
            self._fill = None

    def uniform(self, *shape: int) -> np.ndarray:
        """Uniforms in [0, 1) shaped (runs, *shape); each run's values come from its own stream.

        The result is a view of the buffer (see the module docstring).
        """
        n = prod(shape)
        if self._pos + n > self._size:
            self._refill(n)
        pos = self._pos
        self._pos = pos + n
        out = self._buffer[:, pos:pos + n]
        if len(shape) == 1:
            return out
        return out.reshape((self._runs, *shape))

    def integers(self, high: int, *shape: int) -> np.ndarray:
        """Integers in [0, high) shaped (runs, *shape): ``floor(u * high)``.

        ``u * high < high`` holds in floating point for every u < 1 (the product of
        1 - 2**-53 and any integer below 2**52 rounds below it), so no clamp is needed.
        """
        return (self.uniform(*shape) * high).astype(np.intp)

    def index_other_than(self, n: int, exclude: np.ndarray) -> np.ndarray:
        """Uniform indices in [0, n) shaped like ``exclude`` (runs, ...), never equal to ``exclude``.

        Used for ABC's random neighbour k != i: ``k = floor(u (n - 1))``, then ``k + (k >= i)``.
        """
        k = self.integers(n - 1, *exclude.shape[1:])
        k += k >= exclude
        return k
