"""The solve() API, the problem interface, ABC/GABC behaviour and reproducibility."""
import numpy as np
import pytest

import fkopt
from fkopt.numerics.streams import RunStreams, run_seed_sequence


@pytest.fixture(scope="module")
def case():
    m = fkopt.mechanism("3-rps")
    return fkopt.fk_problem(m, m.ik([9, 13, 622]))


def test_problem_interface(case):
    assert case.dim == 3
    assert case.variable_names == ("alpha", "beta", "z")
    assert case.fitness([9, 13, 622]) < 1e-20
    x = np.zeros((4, 7, 3)) + [0, 0, 500]
    assert case.fitness(x).shape == (4, 7)
    assert case.residuals(x).shape == (4, 7, 3)
    assert np.all(case.fitness(x) > 1)


def test_fk_problem_rejects_bad_joints():
    m = fkopt.mechanism("3-rps")
    with pytest.raises(fkopt.FkoptError, match="expected 3 values"):
        fkopt.fk_problem(m, [1, 2])
    with pytest.raises(fkopt.FkoptError, match="missing d3"):
        fkopt.fk_problem(m, {"d1": 1, "d2": 2})
    with pytest.raises(fkopt.FkoptError, match="allowed: squared, absolute"):
        fkopt.fk_problem(m, [600, 600, 600], objective="cubic")


@pytest.mark.parametrize("name,params", [("abc", {}), ("gabc", {}), ("gabc", {"rule": "zhu2010"})])
def test_swarms_solve_sphere(sphere, name, params):
    res = fkopt.solve(sphere, name, population=20, iterations=400, runs=4, seed=3, params=params)
    assert np.all(res.fitness < 1e-10)
    np.testing.assert_allclose(res.x, 0.3, atol=1e-5)


@pytest.mark.parametrize("name", ["abc", "gabc"])
def test_swarms_solve_3rps_case(case, name):
    res = fkopt.solve(case, name, population=10, iterations=600, runs=10, seed=1)
    assert np.mean(res.fitness) < 1e-10
    np.testing.assert_allclose(res.x[res.median_run], [9, 13, 622], atol=1e-4)


def test_result_records(case):
    res = fkopt.solve(case, "abc", population=10, iterations=50, runs=3, seed=0, target=1e-2,
                      x_history=True)
    assert res.history.shape == (3, 51) and res.x_history.shape == (3, 51, 3)
    assert np.all(np.diff(res.history, axis=1) <= 0), "best-so-far must never increase"
    np.testing.assert_array_equal(res.history[:, -1], res.fitness)
    assert res.evaluation_history[0, 0] == 10
    # one ABC iteration: SN employed + SN onlooker evaluations (+1 per scout)
    assert np.all(np.diff(res.evaluation_history, axis=1) >= 20)
    assert np.all(np.diff(res.evaluation_history, axis=1) <= 21)
    it = res.iterations_to(1e-2)
    reached = ~np.isnan(it)
    assert np.all(res.history[reached, it[reached].astype(int)] < 1e-2)
    for k in np.flatnonzero(reached):
        assert res.history[k, int(it[k]) - 1] >= 1e-2


def test_bounds_respected(case):
    res = fkopt.solve(case, "gabc", population=10, iterations=30, runs=5, seed=0, x_history=True)
    lo, hi = case.bounds[:, 0], case.bounds[:, 1]
    assert np.all((res.x_history >= lo) & (res.x_history <= hi))


def test_stop_at_target_freezes_runs(case):
    res = fkopt.solve(case, "gabc", population=10, iterations=600, runs=8, seed=4, target=1e-5,
                      stop_at_target=True)
    assert np.all(res.fitness < 1e-5)
    assert np.all(res.iterations_done < 600)
    for k in range(8):
        t = res.iterations_done[k]
        assert res.history[k, t] < 1e-5 and res.history[k, t - 1] >= 1e-5
        assert np.all(res.history[k, t:] == res.history[k, t])
        assert res.evaluations[k] == res.evaluation_history[k, t]


@pytest.mark.parametrize("name", ["abc", "gabc"])
def test_batch_equals_one_run_at_a_time(case, name):
    batch = fkopt.solve(case, name, population=10, iterations=100, runs=5, seed=11)
    alone = fkopt.solve(case, name, population=10, iterations=100, runs=5, seed=11, batch=False)
    third = fkopt.solve(case, name, population=10, iterations=100, runs=1, seed=11, run_ids=[3])
    np.testing.assert_array_equal(batch.history, alone.history)
    np.testing.assert_array_equal(batch.x, alone.x)
    np.testing.assert_array_equal(batch.history[3], third.history[0])


def test_seeds_matter(case):
    a = fkopt.solve(case, "abc", population=10, iterations=20, runs=2, seed=1)
    b = fkopt.solve(case, "abc", population=10, iterations=20, runs=2, seed=2)
    assert not np.array_equal(a.history, b.history)
    assert not np.array_equal(a.history[0], a.history[1])


def test_streams_are_spawned_children():
    children = np.random.SeedSequence(42).spawn(5)
    for k in (0, 4):
        expected = np.random.Generator(np.random.PCG64(children[k])).random(10)
        got = np.random.Generator(np.random.PCG64(run_seed_sequence(42, k))).random(10)
        np.testing.assert_array_equal(expected, got)
    s = RunStreams(42, [4])
    np.testing.assert_array_equal(s.uniform(10)[0],
                                  np.random.Generator(np.random.PCG64(children[4])).random(10))


def test_bad_budget_and_params(case):
    with pytest.raises(fkopt.FkoptError, match="population must be at least 2"):
        fkopt.solve(case, "abc", population=1)
    with pytest.raises(fkopt.FkoptError, match="iterations must be at least 1"):
        fkopt.solve(case, "abc", iterations=0)
    with pytest.raises(fkopt.FkoptError, match="runs must be at least 1"):
        fkopt.solve(case, "abc", runs=0)
    with pytest.raises(fkopt.FkoptError, match=r"parameter 'limitt'.*parameters: limit"):
        fkopt.solve(case, "abc", params={"limitt": 3})
    with pytest.raises(fkopt.FkoptError, match="parameter 'rule'"):
        fkopt.algorithm("gabc", rule="nope")
    with pytest.raises(fkopt.FkoptError, match="unknown algorithm 'xyz'; allowed: .*abc"):
        fkopt.solve(case, "xyz")
