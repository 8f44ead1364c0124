"""Artificial bee colony (ABC) of Karaboga (2005), as used by mao2017 (Sec. 2.1) and wang7dof.

docs/models.md "mao2017": fitness-to-quality map fit = 1/(1+f) for f >= 0 (1+|f| otherwise),
onlooker roulette p_i = fit_i / sum(fit), greedy selection, and a scout that replaces a
source whose trial counter exceeds ``limit``.

Choices fkopt makes where the papers are silent (documented, each a named parameter or here):

* ``population`` is the number of food sources SN = employed bees = onlooker bees; one
  iteration is an employed phase (SN evaluations), an onlooker phase (SN evaluations) and at
  most one scout (Karaboga & Basturk's reference code): about 2*SN evaluations, twice a PSO
  iteration of the same population -- compare algorithms at equal evaluations too.
* The neighbour move changes one random coordinate j: v_ij = x_ij + phi (x_ij - x_kj),
  phi ~ U[-1, 1], k != i random, then clipped to the bounds.
* Onlooker roulette: with cumulative qualities c_1 <= ... <= c_SN and u ~ U[0, 1), an onlooker
  takes the first source i with c_i > u * c_SN (source 0 in the degenerate case where every
  quality is 0, i.e. every fitness is infinite).
* Onlookers of one phase act synchronously (vectorised): a source chosen by several onlookers
  keeps the best of their candidates (the lowest fitness; on a tie the onlooker that comes
  first) if it beats the source; each failed attempt adds one to its trial counter.
  Karaboga's sequential loop lets a later onlooker see an earlier one's improvement within
  the phase; the difference is immaterial to convergence and lets every run and every bee
  advance in a handful of array operations.
* ``limit`` defaults to SN * dim (Karaboga & Basturk 2007). A scout replaces the source with
  the most trials (the first of equals) when its counter exceeds ``limit``; at most one per
  run and iteration.
* Order within :meth:`ABC.iterate`: scout, employed, onlooker. The scout acts on the trial
  counters left by the previous iteration -- exactly where Karaboga's reference code runs it,
  at the end of that iteration -- and its fresh source is evaluated in the same fitness call
  as the employed candidates (counted in this iteration's evaluations; one numpy pass
  instead of two). As in the reference code, the best-so-far is memorised before any source
  is abandoned (after the onlooker phase, by :meth:`Algorithm.minimize`), so abandoning a
  stale best source never loses it. A scout after the very last iteration would change
  nothing recorded and is not flown.
* A NaN fitness is treated as +inf (never selected, never accepted).

Random numbers (the order matters for reproducibility; see :mod:`fkopt.numerics.streams`). Per
iteration and run, in this order:

1. scout phase: dim uniforms for a fresh source, drawn every iteration whether or not a scout
   flies, so that each run's stream advances the same way whatever happens in other runs;
2. employed phase, one block of 3*SN uniforms: SN for the coordinates j = floor(u * dim), SN
   for the neighbours k = floor(u * (SN - 1)), k += (k >= i), SN for phi = 2u - 1 (then, for
   GABC's ``zhu2010`` rule, SN more for psi);
3. onlooker phase: SN uniforms for the roulette, then the same block as 2. for the moves.

Speed. At the sizes of the papers (30 runs x 10 bees x 3 variables) the cost of an iteration is
the number of numpy calls; at thousands of rows (cases x runs, :func:`fkopt.solve`) it is the
number of passes over (runs, SN) arrays and whether they are contiguous. The phases are written
for both: one draw per phase, de-interleaved once into contiguous j, k', phi arrays; flat
index arithmetic with per-bee tables built once per state (:class:`_Aux`; the neighbour
k' + (k' >= i) is a table lookup); only the moved coordinate computed and clipped
(:meth:`ABC.move`; a subclass that overrides only the whole-row :meth:`ABC.step` still works,
on the slower general path with identical numbers); ``x``, ``f`` and ``trial`` updated in place
only where a candidate won (an ``np.where`` on a random mask costs a branch misprediction per
element); the onlooker duplicates resolved by two ``np.minimum.at`` scatters (no sort) and a
winner written back as its one moved coordinate; the roulette as a dense count on bee-major
(SN, runs) arrays for small colonies or a vectorised binary search for large ones (the same
integers either way). ``fkopt bench`` measures what an evaluation costs.

On a 3-RPS FK problem with numba installed (unless ``FKOPT_NUMERICS=numpy``), fkopt's own ABC and
GABC (raw selection) run each iteration compiled instead (:func:`fkopt.algorithms.abc_kernels.abc_iteration`:
the same draws in one block per iteration, the same operations, numpy's own ``np.tan``, the
evaluation log's bookkeeping and the best-so-far inside); under :meth:`Algorithm.minimize` many
iterations per compiled call where numpy's tan loop can be called from compiled code
(:meth:`ABC.compiled_advance`, :func:`fkopt.algorithms.abc_kernels.abc_iterations`). Its records
equal these phases bit for bit (tests/test_numerics.py).
"""
from __future__ import annotations

from typing import Literal
from dataclasses import dataclass

import numpy as np
from pydantic import Field

from fkopt.algorithms.base import (Algorithm, Params, State, compiled_step, evaluated, log_arrays, log_kept, row_offsets, rows_of,
                   uniform_in)


class ABCParams(Params):
    limit: int | None = Field(None, ge=1, description="trials without improvement before a source "
                              "is abandoned by a scout; default population * dim")
    selection: Literal["raw", "karaboga"] = Field(
        "raw", description="what the greedy selection and the best-so-far memory compare: raw f "
        "(raw, default) or Karaboga's quality fit = 1/(1+f) (karaboga); in double precision "
        "1/(1+f) == 1 for f below ~1.1e-16, so karaboga cannot tell improvements apart under that "
        "floor and keeps the first source found below it (mao2017 Tab. 3's ~5e-17)")


def quality(f: np.ndarray) -> np.ndarray:
    """Karaboga's fit(f): 1/(1+f) for f >= 0, 1+|f| (= 1-f) otherwise."""
    return np.where(f >= 0, 1.0 / (1.0 + f), 1.0 - f)


#: Colonies up to this size use the dense roulette (SN comparisons per onlooker); larger ones a
#: binary search (O(SN log SN)). Both give the same indices.
DENSE_ROULETTE = 32
#: Up to this many comparisons (runs * SN * SN) the onlookers' dense count is one broadcast
#: comparison (few numpy calls); above it a loop over the SN columns (few passes).
SMALL_ROULETTE = 8192


def roulette(cdf: np.ndarray, u: np.ndarray, dense: bool | None = None) -> np.ndarray:
    """Per run, the first index i with ``cdf[r, i] > u[r, m]`` (0 if there is none).

    ``cdf`` (runs, n) is non-decreasing along axis 1, ``u`` (runs, m); returns (runs, m) indices.
    """
    runs, n = cdf.shape
    if dense is None:
        dense = n <= DENSE_ROULETTE
    if dense:   # count the entries <= u, one column at a time (a reduction over a short last
        # axis, such as argmax over (runs, m, n), costs several times more)
        count = (cdf[:, :1] <= u).astype(np.intp)
        for i in range(1, n):
            count += cdf[:, i:i + 1] <= u
        count[count == n] = 0
        return count
    # Binary search for the count of entries <= u (the first index with cdf > u).
    flat = cdf.ravel()
    base = (row_offsets(runs, n) - 1)[:, None]
    count = np.zeros(u.shape, dtype=np.intp)
    step = 1 << (n.bit_length() - 1)
    while step:
        trial = count + step
        ok = trial <= n
        idx = np.minimum(trial, n)
        idx += base
        ok &= flat[idx] <= u
        count = np.where(ok, trial, count)
        step >>= 1
    count[count == n] = 0
    return count


class _Aux:
    """Index tables and scratch arrays an ABC needs for a given (runs, population, dim), built
    once per state, so that the phases work on contiguous (runs, population) arrays."""

    def __init__(self, shape, bounds):
        runs, population, dim = shape
        n = runs * population
        self.shape = shape
        self.sources = np.broadcast_to(np.arange(population), (runs, population))
        self.offsets = row_offsets(runs, population)[:, None]       # (runs, 1)
        self.scale = np.array([[dim], [population - 1], [2.0]])     # u -> j, k, 2u
        self.cand = (np.arange(n) * dim).reshape(runs, population)  # flat index of x[r, i, 0]
        self.lo, self.hi = bounds[:, 0].copy(), bounds[:, 1].copy()
        self.width = self.hi - self.lo
        self.ids = np.arange(n)
        self.inf = np.full(n, np.inf)
        self.none = np.full(n, n)
        # -- the contiguous fast path (see ABC.employed_phase) --
        per_bee = lambda a: np.repeat(a, population).reshape(runs, population)   # noqa: E731
        self.scale3 = np.array([dim, population - 1, 2.0])[:, None, None]
        self.row_p = per_bee(np.arange(runs) * population)          # flat index of x[r, 0] / dim
        self.row_pd = self.row_p * dim                              # flat index of x[r, 0, 0]
        self.row_d = per_bee(np.arange(runs) * dim)                 # flat index of best_x[r, 0]
        i, k = np.arange(population), np.arange(population - 1)
        # neighbour k' in [0, SN - 1) of bee i is k' + (k' >= i): as a table, times dim
        self.neighbour = ((k + (k >= i[:, None])) * dim).ravel()
        self.neighbour_row = np.tile(i * (population - 1), runs).reshape(runs, population)
        self.w = np.empty((3, runs, population))                     # scaled draws
        self.jk = np.empty((2, runs, population), dtype=np.intp)    # j, k'
        self.v = np.empty((n + runs, dim))                          # candidates (+ fresh scouts)
        self.dense = population <= DENSE_ROULETTE
        if self.dense:
            self.q = np.empty((population, runs))                   # qualities, bee-major
            self.cdf = np.empty((population, runs))
            self.u = np.empty((population, runs))
            self.count = np.empty((population, runs), dtype=np.uint8)
            self.hit = np.empty((population, runs), dtype=np.uint8)
        self.sources_out = np.empty((runs, population), dtype=np.intp)
        self.arrays = None                                          # x, f, trial as checked by _aux


@dataclass(eq=False, kw_only=True)
class ABCState(State):
    """ABC's food sources ``x``/``f`` with their trial counters.

    The phases update ``x``, ``f`` and ``trial`` in place (C-contiguous arrays of the state's
    own; :func:`_aux` replaces any other by a contiguous copy first).
    """

    trial: np.ndarray                   # (runs, population) failed attempts per source
    limit: int                          # trials before a scout abandons the source
    aux: _Aux | None = None             # index arrays for this shape, built on first use
    pending: tuple | None = None        # scout sources placed but not yet evaluated


def _own(a: np.ndarray, dtype) -> np.ndarray:
    """``a`` itself when it is a C-contiguous writable array that owns its data, else a copy."""
    if a.dtype == dtype and a.flags.c_contiguous and a.flags.writeable and a.base is None:
        return a
    return np.array(a, dtype=dtype, order="C")


def _aux(state: ABCState, problem) -> _Aux:
    aux = state.aux
    if aux is not None and aux.arrays is not None and (
            aux.arrays[0] is state.x and aux.arrays[1] is state.f and aux.arrays[2] is state.trial):
        return aux                                      # the arrays checked last time
    if aux is None or aux.shape != state.x.shape:
        aux = state.aux = _Aux(state.x.shape, np.asarray(problem.bounds, dtype=float))
    state.x, state.f, state.trial = _own(state.x, float), _own(state.f, float), _own(state.trial, np.int64)
    aux.arrays = (state.x, state.f, state.trial)
    return aux


def _compiled_iteration(fitness):
    """:func:`fkopt.algorithms.abc_kernels.abc_iteration` on a mechanism's compiled fitness."""
    from fkopt.algorithms.abc_kernels import abc_iteration   # lazy: imports numba: only once the compiled path runs
    return abc_iteration(fitness)


def _compiled_iterations(fitness):
    """:func:`fkopt.algorithms.abc_kernels.abc_iterations` on a mechanism's compiled fitness (None
    without numpy's ufunc loop)."""
    from fkopt.algorithms.abc_kernels import abc_iterations  # lazy: imports numba: only once the compiled path runs
    return abc_iterations(fitness)


class ABC(Algorithm):
    name = "abc"
    blas_free = True          # elementwise numpy only: no BLAS kernel decides its bits
    Params = ABCParams
    evaluations_per_iteration = "2*population (+1 per scout)"

    # -- phases ------------------------------------------------------------------------------
    def initialize(self, problem, population, streams, x0, iterations):
        x = uniform_in(problem.bounds, streams.uniform(population, problem.dim))
        f = np.fmin(problem.fitness(x), np.inf)
        runs = streams.runs
        limit = self.params.limit or population * problem.dim
        return ABCState(x=x, f=f, trial=np.zeros(f.shape, dtype=np.int64), limit=limit,
                        evaluations=np.full(runs, population, dtype=np.int64))

    #: Does the move read the best-so-far point (then it is refreshed between the phases)?
    uses_best = False

    def iterate(self, state, problem, streams):
        fused = self._compiled_iteration(problem)
        if fused is not None:                      # a built-in fitness with a compiled iteration
            return self._iterate_compiled(state, problem, streams, *fused)
        # The scout of the previous iteration's trials flies first; its fresh source is
        # evaluated together with the employed candidates (one fitness call, not two).
        self.scout_phase(state, problem, streams, evaluate=False)
        self.employed_phase(state, problem, streams)
        if self.uses_best:
            self.update_best(state)
        self.onlooker_phase(state, problem, streams)

    def compiled_rule(self) -> int | None:
        """The move as the compiled iteration knows it (0: ABC's; GABC: 1 mao2017, 2 zhu2010),
        or None when it must run on numpy: a subclass (its own phases or moves), or
        ``selection: karaboga``."""
        return 0 if type(self) is ABC and self.params.selection == "raw" else None

    def _compiled_iteration(self, problem):
        """(compiled iteration, absolute objective, rule) or None (:func:`compiled_step`)."""
        rule = self.compiled_rule()
        fused = None if rule is None else compiled_step(problem, _compiled_iteration)
        return None if fused is None else (*fused, rule)

    def _iterate_compiled(self, state, problem, streams, step, absolute, rule):
        """:meth:`iterate` in one compiled pass (:func:`fkopt.algorithms.abc_kernels.abc_iteration`): the
        same draws (one block per iteration holding the phases' draws in their order), the same
        operations (numpy's ``np.tan`` included), the same log reports, the best-so-far folded in."""
        width, J, best_x, best_f, C = self._compiled_inputs(state, problem, rule)
        runs = state.f.shape[0]
        u = streams.uniform(width)
        # the evaluation log's bookkeeping runs in the same pass (EvaluationLog.add value by value)
        # (a target per row: the numpy path evaluates the fresh scouts in a fitness call of their own)
        evaluations, kept = step(state.x, state.f, state.trial, best_x, best_f, u, state.limit, rule, C,
                                 problem.bounds, J, absolute, log_arrays(state, runs), problem.cases is not None,
                                 np.ascontiguousarray(state.evaluations, dtype=np.int64))
        log_kept(state, kept)
        state.best_x, state.best_f, state.best_folded = best_x, best_f, True
        state.evaluations = evaluations         # + 2 SN, + 1 where a scout flew

    def _compiled_inputs(self, state, problem, rule):
        """What the compiled iterations take besides the state (x, f, trial made C-contiguous arrays
        of our own first): the uniforms one iteration draws (scout dim, then per phase 3 SN, 4 with
        zhu2010's psi, and the onlookers' SN), the target rows J, copies of the best-so-far (the
        kernels refresh it in place -- GABC's between the phases, minimize's update_best after
        them -- so new arrays, as update_best makes) and zhu2010's C."""
        _aux(state, problem)
        runs, population, dim = state.x.shape
        if problem.cases is not None:
            problem._check_cases(state.x)
        width = dim + 2 * (4 if rule == 2 else 3) * population + population
        return (width, problem._joint_rows(state.x.shape[:-1]), state.best_x.copy(), state.best_f.copy(),
                getattr(self.params, "C", 0.0))

    def compiled_advance(self, problem):
        """Several iterations per compiled call (:meth:`fkopt.algorithms.base.Algorithm.compiled_advance`)
        where the iteration is compiled (:meth:`compiled_rule`, :func:`compiled_step`) and numpy's
        ufunc loop is callable from compiled code (:func:`fkopt.algorithms.abc_kernels.abc_iterations`),
        else None (minimize then calls :meth:`iterate`)."""
        rule = self.compiled_rule()
        got = None if rule is None else compiled_step(problem, _compiled_iterations)
        if got is None or got[0] is None:
            return None
        kernel, absolute = got
        return lambda state, streams, first, last, history, evaluations, x_history: self._advance_compiled(
            state, problem, streams, first, last, history, evaluations, x_history, kernel, absolute, rule)

    def _advance_compiled(self, state, problem, streams, first, last, history, evaluations, x_history, kernel,
                          absolute, rule):
        """Iterations first..k in one compiled call (k <= last: as many as
        :data:`fkopt.algorithms.abc_kernels.ITERATIONS_UNIFORMS` uniforms allow, at least one); the
        draws of iteration t are the block :meth:`_iterate_compiled` draws, taken for all k in one
        call (the same values: a stream hands out its values in order). Returns k."""
        from fkopt.algorithms.abc_kernels import ITERATIONS_UNIFORMS  # lazy: numba
        width, J, best_x, best_f, C = self._compiled_inputs(state, problem, rule)
        runs = state.f.shape[0]
        k = max(1, min(last + 1 - first, ITERATIONS_UNIFORMS // (runs * width)))
        u = streams.uniform(k * width)
        evals = np.array(state.evaluations, dtype=np.int64)
        log = log_arrays(state, runs)
        done = 0
        while done < k:                             # more than one call only when the log's arrays fill up
            n, kept = kernel(state.x, state.f, state.trial, best_x, best_f, u[:, done * width:], width, state.limit,
                             rule, C, problem.bounds, J, absolute, log, problem.cases is not None, evals, history,
                             evaluations, x_history, first + done)
            log_kept(state, kept)
            done += n
        state.best_x, state.best_f, state.evaluations = best_x, best_f, evals
        return first + k - 1

    def step(self, state, xs, xk, phi, streams):
        """The move added to the chosen coordinate, on whole rows (overridden by GABC).

        ``xs``, ``xk``: the sources and neighbours, (runs, n, dim); ``phi``: (runs, n, 1). Only
        coordinate j of the result is used. A subclass that overrides only :meth:`step` gets
        this whole-row evaluation; fkopt's own classes override :meth:`move` as well, which
        computes the same numbers on the chosen coordinate alone (faster).
        """
        return phi * (xs - xk)

    def move(self, state, xs, xk, j, phi, streams):
        """New value of the chosen coordinate j, before clipping: ``xs + step``.

        ``xs``, ``xk``, ``j``, ``phi``: (runs, n) -- coordinate j of the source and of the
        neighbour, the coordinate index and phi. Returns a new array (the inputs are not changed).
        """
        out = np.subtract(xs, xk)
        out *= phi
        return np.add(xs, out, out=out)             # xs + phi * (xs - xk)

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        # A subclass customising only the whole-row step keeps its semantics (slower path).
        cls._row_step = cls.step is not ABC.step and cls.move is ABC.move
        # A customised move may read state.best_x: refresh it between the phases unless the
        # subclass says otherwise.
        if "uses_best" not in cls.__dict__ and (cls.step is not ABC.step or cls.move is not ABC.move):
            cls.uses_best = True

    _row_step = False

    def candidates(self, state, sources, problem, streams):
        """Neighbour candidates of ``sources`` (runs, n): one coordinate moved towards/away from k."""
        return self._propose(state, sources, problem, streams)[0]

    def _propose(self, state, sources, problem, streams):
        """``(v, pos, new, old)``: the candidates and, on the fast path, the flat positions of
        their moved coordinate in ``v`` with its new (clipped) and old values (else Nones).

        The general form of the phases' candidate step (any ``sources``, whole-row steps);
        the phases use :meth:`_moves` on their contiguous arrays (the same numbers)."""
        aux = _aux(state, problem)
        x = state.x
        runs, population, dim = x.shape
        n = sources.shape[1]
        w = streams.uniform(3, n) * aux.scale
        jk = w[:, :2].astype(np.intp)
        j, k = jk[:, 0], jk[:, 1]
        k += k >= sources
        phi = w[:, 2] - 1.0
        k += aux.offsets
        employed = sources is aux.sources
        if self._row_step:
            x2 = x.reshape(runs * population, dim)
            xs = x if employed else x2[sources + aux.offsets]
            moved = xs + self.step(state, xs, x2[k], phi[..., None], streams)
            v = np.where(np.arange(dim) == j[..., None], moved, xs)
            np.maximum(v, aux.lo, out=v)
            np.minimum(v, aux.hi, out=v)
            return v, None, None, None
        # Only coordinate j changes: work on flat (runs, n) arrays of that coordinate.
        xf = x.reshape(-1)
        pos = (aux.cand if n == population else (np.arange(runs * n) * dim).reshape(runs, n)) + j
        if employed:
            v = x.copy()
            src = pos
        else:
            v = x.reshape(runs * population, dim).take(sources + aux.offsets, axis=0)
            src = (sources + aux.offsets) * dim
            src += j
        k *= dim
        k += j
        old = xf.take(src)
        m = self.move(state, old, xf.take(k), j, phi, streams)
        np.maximum(m, aux.lo.take(j), out=m)
        np.minimum(m, aux.hi.take(j), out=m)
        v.reshape(-1)[pos] = m
        return v, pos, m, old

    def _moves(self, state, aux, streams, sources=None):
        """The phases' candidate step on contiguous (runs, population) arrays: draws one block
        of 3 * population uniforms per run (j, k', phi as in :meth:`_propose`) and returns
        ``(pos, m, j)``: the flat index in ``x`` of the moved coordinate of each candidate's
        source, its new (clipped) value and the coordinate index j. ``sources``: the onlookers' chosen sources (None:
        the employed bees, source i for bee i)."""
        x = state.x
        xf = x.reshape(-1)
        runs, population, dim = x.shape
        u = streams.uniform(3, population)                          # (runs, 3, SN) view
        w = aux.w
        np.multiply(u.transpose(1, 0, 2), aux.scale3, out=w)         # u*dim, u*(SN-1), 2u
        jk = aux.jk
        np.copyto(jk, w[:2], casting="unsafe")                      # floor (u >= 0)
        j, k = jk
        phi = w[2]
        phi -= 1.0
        if sources is None:
            k += aux.neighbour_row
            pos = aux.cand + j
        else:
            nb = np.multiply(sources, population - 1)
            k += nb
            pos = np.add(sources, aux.row_p, out=nb)
            pos *= dim
            pos += j
        kpos = aux.neighbour.take(k)                                # dim * (k' + (k' >= i))
        kpos += aux.row_pd
        kpos += j
        m = self.move(state, xf.take(pos), xf.take(kpos), j, phi, streams)
        np.maximum(m, aux.lo.take(j), out=m)
        np.minimum(m, aux.hi.take(j), out=m)
        return pos, m, j

    def better(self, new: np.ndarray, old: np.ndarray) -> np.ndarray:
        """Greedy selection: does ``new`` replace ``old``? (``selection`` parameter)."""
        if self.params.selection == "karaboga":
            return quality(new) > quality(old)
        return new < old

    def update_best(self, state: State) -> None:
        """As :meth:`Algorithm.update_best`; with ``selection: karaboga`` compared on quality."""
        if self.params.selection != "karaboga":
            return Algorithm.update_best(state)
        runs, population = state.f.shape
        flat = state.f.argmin(axis=1) + row_offsets(runs, population)
        fb = state.f.ravel()[flat]
        better = quality(fb) > quality(state.best_f)
        state.best_f = np.where(better, fb, state.best_f)
        state.best_x = np.where(better[:, None], state.x.reshape(runs * population, -1)[flat], state.best_x)

    def _evaluate_candidates(self, state, problem, v) -> np.ndarray:
        """Fitness of the candidates ``v`` (runs * SN, dim), and of the scouts' fresh sources
        placed by :meth:`scout_phase` (``evaluate=False``), which it writes into ``state.f``."""
        runs, population, dim = state.x.shape
        n = runs * population
        pending, state.pending = state.pending, None
        if pending is None:
            fv = np.fmin(problem.fitness(v.reshape(state.x.shape)), np.inf)
            evaluated(state, fv)
            return fv
        slots, fresh, count = pending
        f = state.f.reshape(-1)
        if getattr(problem, "cases", None) is None:     # one call for both
            both = state.aux.v[:n + len(fresh)]
            both[n:] = fresh
            both = np.fmin(problem.fitness(both), np.inf)
            fv = both[:n].reshape(state.f.shape)
            f[slots] = both[n:]
            evaluated(state, fv)
            evaluated(state, both[n:], slots // population)
        else:   # a target per row: the scouts' rows (same numbers, a second call)
            fv = np.fmin(problem.fitness(v.reshape(state.x.shape)), np.inf)
            f[slots] = np.fmin(rows_of(problem, slots // population).fitness(fresh), np.inf)
            evaluated(state, fv)
            evaluated(state, f[slots], slots // population)
        state.evaluations = state.evaluations + count
        return fv

    def employed_phase(self, state, problem, streams):
        aux = _aux(state, problem)
        if self._row_step:
            return self._employed_rows(state, problem, streams, aux)
        runs, population, dim = state.x.shape
        n = runs * population
        pos, m, _ = self._moves(state, aux, streams)
        v = aux.v[:n]
        np.copyto(v, state.x.reshape(n, dim))
        v.reshape(-1)[pos] = m
        fv = self._evaluate_candidates(state, problem, v)
        better = self.better(fv, state.f)
        # Greedy selection, only where a candidate won (x is v with the old value elsewhere).
        won = better.reshape(-1).nonzero()[0]
        state.f.reshape(-1)[won] = fv.reshape(-1)[won]
        trial = state.trial.reshape(-1)
        trial += 1
        trial[won] = 0
        state.x.reshape(-1)[pos.reshape(-1)[won]] = m.reshape(-1)[won]
        state.evaluations = state.evaluations + population

    def _employed_rows(self, state, problem, streams, aux):
        """:meth:`employed_phase` for a subclass that customises only the whole-row :meth:`step`."""
        runs, population, dim = state.x.shape
        v, _, _, _ = self._propose(state, aux.sources, problem, streams)
        np.copyto(aux.v[:runs * population], v.reshape(-1, dim))
        fv = self._evaluate_candidates(state, problem, aux.v[:runs * population])
        better = self.better(fv, state.f)
        state.x = np.where(better[..., None], v, state.x)
        state.f = np.where(better, fv, state.f)
        state.trial = np.where(better, 0, state.trial + 1)
        state.evaluations = state.evaluations + population

    def _choose_sources(self, state, aux, streams) -> np.ndarray:
        """The onlookers' roulette (module docstring): draws SN uniforms per run, returns the
        chosen sources (runs, SN). Small colonies: the dense count of :func:`roulette` on
        bee-major (SN, runs) arrays, where every comparison is one contiguous pass."""
        f = state.f
        runs, population = f.shape
        if not aux.dense or runs * population * population <= SMALL_ROULETTE:
            q = np.divide(1.0, np.add(1.0, f)) if f.min() >= 0 else quality(f)
            cdf = q.cumsum(axis=1)
            u = streams.uniform(population) * cdf[:, -1:]
            if not aux.dense:
                return roulette(cdf, u, dense=False)
            count = (cdf[:, None, :] <= u[:, :, None]).sum(axis=2)     # few rows: one comparison
            count[count == population] = 0
            return count
        q, cdf = aux.q, aux.cdf
        if f.min() >= 0:                                # quality 1 / (1 + f) (f < 0: quality())
            np.add(f.T, 1.0, out=q)
            np.divide(1.0, q, out=q)
        else:
            np.copyto(q, quality(f).T)
        np.cumsum(q, axis=0, out=cdf)                   # the same sequential sums as along axis 1
        u = aux.u
        np.multiply(streams.uniform(population).T, cdf[-1], out=u)
        count, hit = aux.count, aux.hit
        np.less_equal(cdf[0], u, out=count.view(np.bool_))
        for i in range(1, population):
            np.less_equal(cdf[i], u, out=hit.view(np.bool_))
            count += hit
        if count.max() == population:                   # no cumulative quality above u: source 0
            count[count == population] = 0
        out = aux.sources_out
        np.copyto(out, count.T)
        return out

    def onlooker_phase(self, state, problem, streams):
        aux = _aux(state, problem)
        if self._row_step:
            return self._onlooker_rows(state, problem, streams, aux)
        runs, population, dim = state.x.shape
        n = runs * population
        sources = self._choose_sources(state, aux, streams)
        flat = np.add(sources, aux.row_p).reshape(-1)   # flat index of each onlooker's source
        pos, m, j = self._moves(state, aux, streams, sources)
        v = aux.v[:n]
        state.x.reshape(n, dim).take(flat, axis=0, out=v)
        v.reshape(-1)[aux.cand + j] = m
        fv = np.fmin(problem.fitness(v.reshape(state.x.shape)), np.inf).reshape(-1)
        evaluated(state, fv.reshape(runs, population))
        # Resolve onlookers that chose the same source: per source, the lowest candidate
        # fitness, and the first onlooker reaching it.
        best = aux.inf.copy()
        np.minimum.at(best, flat, fv)
        hit = (fv == best.take(flat)).nonzero()[0]
        first = aux.none.copy()
        np.minimum.at(first, flat.take(hit), hit)
        f = state.f.reshape(-1)
        won = self.better(best, f).nonzero()[0]         # sources replaced by an onlooker's candidate
        winner = first.take(won)
        state.x.reshape(-1)[pos.reshape(-1).take(winner)] = m.reshape(-1).take(winner)
        f[won] = best.take(won)
        trial = state.trial.reshape(-1)
        trial += np.bincount(flat, minlength=n)
        trial[won] = 0
        state.evaluations = state.evaluations + population

    def _onlooker_rows(self, state, problem, streams, aux):
        """:meth:`onlooker_phase` for a subclass that customises only the whole-row :meth:`step`."""
        runs, population = state.f.shape
        cdf = quality(state.f).cumsum(axis=1)
        u = streams.uniform(population) * cdf[:, -1:]
        sources = roulette(cdf, u)
        v = self.candidates(state, sources, problem, streams)
        fv = np.fmin(problem.fitness(v), np.inf).ravel()
        evaluated(state, fv.reshape(runs, population))
        size = runs * population
        flat = (sources + aux.offsets).ravel()
        best = aux.inf.copy()
        np.minimum.at(best, flat, fv)
        hit = fv == best.take(flat)
        first = aux.none.copy()
        np.minimum.at(first, flat[hit], aux.ids[hit])
        f = state.f.ravel()
        ok = self.better(best, f)
        np.minimum(first, size - 1, out=first)
        shape = state.x.shape
        won = v.reshape(size, -1).take(first, axis=0).reshape(-1)
        state.x = np.where(ok.repeat(shape[-1]), won, state.x.reshape(-1)).reshape(shape)
        state.f = np.where(ok, best, f).reshape(runs, population)
        trial = state.trial.reshape(-1) + np.bincount(flat, minlength=size)
        state.trial = np.where(ok, 0, trial).reshape(runs, population)
        state.evaluations = state.evaluations + population

    def scout_phase(self, state, problem, streams, evaluate: bool = True):
        """Abandon the source with the most trials (first of equals) if they exceed ``limit``.

        With ``evaluate=False`` the fresh sources are placed with fitness +inf and evaluated by
        the next :meth:`employed_phase` (together with its candidates, before its greedy step).
        """
        aux = _aux(state, problem)
        runs, population = state.f.shape
        # Drawn for every run so each run's stream advances the same way whatever the others do.
        u = streams.uniform(problem.dim)
        trial = state.trial
        over = (trial.reshape(-1) > state.limit).nonzero()[0]
        if over.size == 0:
            return
        rows = over // population                       # runs with a source over the limit
        rows = rows[np.concatenate(([True], rows[1:] != rows[:-1]))]
        slots = trial[rows].argmax(axis=1)
        slots += rows * population
        scout = np.zeros(runs, dtype=bool)
        scout[rows] = True
        fresh = aux.lo + u[rows] * aux.width
        state.x.reshape(runs * population, -1)[slots] = fresh
        trial.reshape(-1)[slots] = 0
        f = state.f.reshape(-1)
        if evaluate:
            f[slots] = np.fmin(rows_of(problem, rows).fitness(fresh), np.inf)
            evaluated(state, f[slots], rows)
            state.evaluations = state.evaluations + scout
        else:
            f[slots] = np.inf
            state.pending = (slots, fresh, scout)
