"""Engine invariants: batching never changes the numbers, streams are the spawned children,
the fast paths compute exactly what the reference paths compute."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import fkopt
from fkopt.numerics import streams as streams_mod
from fkopt.algorithms.abc import ABC, roulette
from fkopt.algorithms.gabc import GABC
from fkopt.numerics.streams import RunStreams, run_seed_sequence

ARRAYS = ("x", "fitness", "history", "x_history", "evaluation_history", "iterations_done")


@pytest.fixture(scope="module")
def problem():
    m = fkopt.mechanism("3-rps")
    return fkopt.fk_problem(m, m.ik([9, 13, 622]))


@pytest.fixture(scope="module")
def printed():
    # the printed inputs of mao2017 have no exact zero: fitness floors differ between runs
    return fkopt.fk_problem(fkopt.mechanism("3-rps"), [598.8495, 671.5847, 629.4955])


class Sphere:
    variable_names = ("a", "b", "c", "d")
    variable_units = ("", "", "", "")
    bounds = np.array([[-5.0, 5.0]] * 4)
    dim = 4

    def fitness(self, x):
        x = np.asarray(x)
        return (x * x).sum(axis=-1)


def assert_same(a, b, rows=None):
    for name in ARRAYS:
        va, vb = getattr(a, name), getattr(b, name)
        if rows is not None:
            vb = vb[rows]
        np.testing.assert_array_equal(va, vb, err_msg=name)


CASES = [("abc", {}), ("gabc", {}), ("gabc", {"rule": "zhu2010"})]
IDS = ["abc", "gabc-mao2017", "gabc-zhu2010"]


@pytest.mark.parametrize("name,params", CASES, ids=IDS)
@pytest.mark.parametrize("stop", [False, True], ids=["full", "stop_at_target"])
def test_batch_equals_one_run_at_a_time(problem, name, params, stop):
    kw = dict(population=10, iterations=150, runs=6, seed=11, params=params, x_history=True,
              target=1e-8 if stop else None, stop_at_target=stop)
    batch = fkopt.solve(problem, name, **kw)
    alone = fkopt.solve(problem, name, batch=False, **kw)
    assert_same(batch, alone)
    if stop:   # the stop really happened at different iterations for different runs
        assert (batch.iterations_done < 150).sum() >= 3 and len(set(batch.iterations_done)) > 1


@pytest.mark.parametrize("name,params", CASES, ids=IDS)
def test_run_k_alone_equals_run_k_in_batch(printed, name, params):
    kw = dict(population=10, iterations=120, seed=5, params=params, x_history=True)
    batch = fkopt.solve(printed, name, runs=8, **kw)
    for k in (0, 3, 7):
        alone = fkopt.solve(printed, name, runs=1, run_ids=[k], **kw)
        assert_same(alone, batch, rows=[k])
    # any subset, in any order
    sub = fkopt.solve(printed, name, runs=3, run_ids=[6, 1, 4], **kw)
    assert_same(sub, batch, rows=[6, 1, 4])


@pytest.mark.parametrize("population", [3, 40], ids=["tiny", "large-colony"])
def test_scouts_and_large_colonies_are_batch_independent(population):
    # limit=2 makes scouts fly in most iterations; 40 sources use the binary-search roulette
    kw = dict(population=population, iterations=60, runs=5, seed=2, params={"limit": 2})
    batch = fkopt.solve(Sphere(), "gabc", **kw)
    alone = fkopt.solve(Sphere(), "gabc", batch=False, **kw)
    assert_same(batch, alone)
    # scouts cost evaluations beyond the 2 * population per iteration
    assert (batch.evaluations > population + 60 * 2 * population).all()


def test_stop_at_target_records_hold_after_the_stop(problem):
    r = fkopt.solve(problem, "gabc", population=10, iterations=200, runs=4, seed=1,
                    target=1e-6, stop_at_target=True)
    for k, t in enumerate(r.iterations_done):
        assert r.history[k, t] < 1e-6 and (t == 0 or r.history[k, t - 1] >= 1e-6)
        assert (r.history[k, t:] == r.history[k, t]).all()
        assert (r.evaluation_history[k, t:] == r.evaluation_history[k, t]).all()


@pytest.mark.parametrize("seed,n", [(0, 1), (1, 30), (12345, 7)])
def test_run_streams_are_the_spawned_children(seed, n):
    children = np.random.SeedSequence(seed).spawn(n)
    s = RunStreams(seed, range(n))
    got = s.uniform(5000)         # crosses no refill; the next call does
    more = s.uniform(3, 4000)
    for k, child in enumerate(children):
        assert child.spawn_key == run_seed_sequence(seed, k).spawn_key
        assert child.entropy == run_seed_sequence(seed, k).entropy
        g = np.random.Generator(np.random.PCG64(child))
        np.testing.assert_array_equal(got[k], g.random(5000))
        np.testing.assert_array_equal(more[k].ravel(), g.random(12000))


@settings(max_examples=25, deadline=None)
@given(st.lists(st.integers(1, 900), min_size=1, max_size=12), st.integers(1, 300))
def test_stream_values_do_not_depend_on_chunking(sizes, chunk):
    ref = RunStreams(3, [2, 9])
    old = streams_mod.CHUNK
    streams_mod.CHUNK = chunk
    try:
        s = RunStreams(3, [2, 9])
        parts = [s.uniform(n) for n in sizes]
    finally:
        streams_mod.CHUNK = old
    np.testing.assert_array_equal(np.concatenate(parts, axis=1), ref.uniform(sum(sizes)))
    # run 9 alone draws what it draws beside run 2
    np.testing.assert_array_equal(RunStreams(3, [9]).uniform(sum(sizes))[0],
                                  RunStreams(3, [2, 9]).uniform(sum(sizes))[1])


def test_integers_and_neighbours():
    s = RunStreams(0, range(4))
    i = s.integers(7, 1000)
    assert i.min() == 0 and i.max() == 6
    excl = np.broadcast_to(np.arange(5), (4, 5))
    for _ in range(200):
        k = s.index_other_than(5, excl)
        assert ((k >= 0) & (k < 5) & (k != excl)).all()


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 70), st.integers(1, 40), st.integers(0, 2**32 - 1), st.booleans())
def test_roulette_dense_equals_binary_search(n, m, seed, zeros):
    rng = np.random.default_rng(seed)
    fit = rng.random((3, n))
    if zeros:   # ties and flat stretches in the cumulative sums, and an all-zero run
        fit[rng.random((3, n)) < 0.5] = 0.0
        fit[0] = 0.0
    cdf = fit.cumsum(axis=1)
    u = rng.random((3, m)) * cdf[:, -1:]
    dense, search = roulette(cdf, u, dense=True), roulette(cdf, u, dense=False)
    np.testing.assert_array_equal(dense, search)
    # the definition: first index whose cumulative value exceeds u (0 when there is none)
    for r in range(3):
        for c in range(m):
            above = np.flatnonzero(cdf[r] > u[r, c])
            assert dense[r, c] == (above[0] if above.size else 0)


class RowStepGABC(GABC):
    """GABC written the way a subclass that only overrides the whole-row ``step`` would be."""

    name = "rowstep-gabc"
    move = ABC.move
    uses_best = True


def test_coordinate_fast_path_equals_whole_row_step(problem):
    assert RowStepGABC._row_step and not GABC._row_step
    for rule in ("mao2017", "zhu2010"):
        fast = fkopt.solve(problem, GABC(rule=rule), population=10, iterations=100, runs=4, seed=8)
        slow = fkopt.solve(problem, RowStepGABC(rule=rule), population=10, iterations=100, runs=4, seed=8)
        assert_same(fast, slow)


def test_abc_and_gabc_converge_on_a_sphere():
    for name in ("abc", "gabc"):
        r = fkopt.solve(Sphere(), name, population=20, iterations=300, runs=3, seed=0)
        assert (r.fitness < 1e-8).all(), (name, r.fitness)
        assert (np.diff(r.history, axis=1) <= 0).all()          # best-so-far never worsens


def test_mao2017_case_is_solved(problem):
    # SPEC.md mao2017 Tab. 3: ABC and GABC reach ~1e-17 within 600 iterations (30 runs)
    for name in ("abc", "gabc"):
        r = fkopt.solve(problem, name, population=10, iterations=600, runs=30, seed=1)
        assert np.median(r.fitness) < 1e-12, name
        assert r.evaluations.min() >= 600 * 20 + 10


@settings(max_examples=30, deadline=None)
@given(st.floats(-60, 60), st.floats(-60, 60), st.floats(100, 900),
       st.floats(50, 400), st.floats(20, 300))
def test_lean_rps3_ik_equals_textbook_form(alpha, beta, z, ra, rb):
    m = fkopt.mechanism("3-rps", ra=ra, rb=rb)
    pose = [alpha, beta, z]
    np.testing.assert_allclose(m.ik(pose), m.ik_reference(pose), rtol=1e-13, atol=1e-11)
    batch = m.ik(np.array([pose] * 5).reshape(5, 1, 3))
    np.testing.assert_array_equal(batch[3, 0], m.ik(pose))     # elementwise: batch-independent
