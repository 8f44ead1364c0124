"""Adapters of other libraries' optimisers: counting, budget, seeds, processes, errors."""
import numpy as np
import pytest

import fkopt
from fkopt.adapters.base import Counter, checkpoints
from fkopt.errors import FkoptError
from conftest import Sphere


class CountingSphere(Sphere):
    """Counts the points the library had evaluated, independently of fkopt's wrapper."""

    def __init__(self, *a, **k):
        super().__init__(*a, **k)
        self.points = 0

    def fitness(self, x):
        x = np.asarray(x)
        self.points += int(np.prod(x.shape[:-1]))
        return super().fitness(x)


def _libraries():
    out = ["scipy:differential_evolution", "scipy:dual_annealing"]
    try:
        import pymoo  # noqa: F401
        out += ["pymoo:DE", "pymoo:GA", "pymoo:PSO"]
    except ImportError:
        pass
    try:
        import niapy  # noqa: F401
        out += ["niapy:ArtificialBeeColonyAlgorithm", "niapy:DifferentialEvolution"]
    except ImportError:
        pass
    return out


@pytest.mark.parametrize("name", _libraries())
def test_budget_counting_and_records(name):
    problem = CountingSphere(dim=4)
    budget = 437                                   # not a multiple of any population
    params = {"evaluations": budget, "workers": 1}
    if name == "scipy:differential_evolution":
        params.update(tol=0, atol=0)               # no early convergence: the budget ends it
    r = fkopt.solve(problem, name, population=12, iterations=20, runs=2, seed=5, params=params)
    # the wrapper's count is the problem's own count, and never above the budget
    assert problem.points == r.evaluations.sum()
    assert np.all(r.evaluations <= budget)
    if name != "scipy:dual_annealing":             # dual annealing may finish its schedule first
        assert np.all(r.evaluations == budget)
    # records on fkopt's iteration axis: monotone best-so-far, checkpoints of the evaluations
    assert r.history.shape == (2, 21) and np.all(np.diff(r.history, axis=1) <= 0)
    e = checkpoints(12, 20, budget)
    assert e[0] == 12 and e[-1] == budget
    np.testing.assert_array_equal(r.evaluation_history, np.minimum(e, r.evaluations[:, None]))
    # the recorded best point has the recorded fitness
    np.testing.assert_allclose(problem.fitness(r.x), r.fitness, rtol=1e-12, atol=0)
    assert np.all(r.fitness < problem.fitness(np.zeros(4)) + 1.0)


def test_run_seeds_do_not_depend_on_the_batch_or_processes():
    p = Sphere(dim=3)
    name = "scipy:differential_evolution"
    batch = fkopt.solve(p, name, population=9, iterations=10, runs=3, seed=2, params={"workers": 1})
    alone = fkopt.solve(p, name, population=9, iterations=10, runs=1, seed=2, run_ids=[2])
    pooled = fkopt.solve(p, name, population=9, iterations=10, runs=3, seed=2, params={"workers": 2})
    np.testing.assert_array_equal(batch.history[2], alone.history[0])
    np.testing.assert_array_equal(batch.history, pooled.history)
    np.testing.assert_array_equal(batch.x, pooled.x)
    assert not np.array_equal(batch.history[0], batch.history[1])    # runs differ


def test_niapy_runs_in_worker_processes_reproducibly():
    pytest.importorskip("niapy")
    p = Sphere(dim=3)
    name = "niapy:ArtificialBeeColonyAlgorithm"
    one = fkopt.solve(p, name, population=10, iterations=10, runs=2, seed=4, params={"workers": 1})
    two = fkopt.solve(p, name, population=10, iterations=10, runs=2, seed=4, params={"workers": 2})
    np.testing.assert_array_equal(one.history, two.history)
    assert np.all(one.evaluations == 110)


def test_stop_at_target_ends_the_run_at_that_evaluation():
    p = CountingSphere(dim=2)
    r = fkopt.solve(p, "scipy:differential_evolution", population=10, iterations=200, runs=2, seed=1,
                    target=1e-6, stop_at_target=True, params={"tol": 0, "atol": 0, "polish": False})
    assert np.all(r.fitness < 1e-6)
    assert np.all(r.evaluations < 10 * 201) and p.points == r.evaluations.sum()
    # the first record below the target is where the run stopped
    for k in range(2):
        t = r.iterations_done[k]
        assert r.history[k, t] < 1e-6 and (t == 0 or r.history[k, t - 1] >= 1e-6)


def test_counter_truncates_a_batch_at_the_budget():
    p = CountingSphere(dim=2)
    c = Counter(p, budget=5)
    c.batch(np.ones((3, 2)))
    with pytest.raises(Exception) as info:
        c.batch(np.zeros((4, 2)))          # only 2 of these 4 are evaluated
    assert type(info.value).__name__ == "_Stop"
    assert c.n == 5 and p.points == 5
    tr = c.trace()
    assert tr.evals.tolist() == [1, 4] and tr.f[-1] == p.fitness(np.zeros(2))


def test_params_pass_through_and_bad_params_fail_before_running():
    p = Sphere(dim=2)
    r = fkopt.solve(p, "scipy:differential_evolution", population=10, iterations=5, runs=1,
                    params={"mutation": 0.7, "recombination": 0.5, "strategy": "best1bin"})
    assert r.params["strategy"] == "best1bin" and r.params["mutation"] == 0.7
    with pytest.raises(FkoptError, match="scipy:differential_evolution.*no parameter 'mutaton'"):
        fkopt.algorithm("scipy:differential_evolution", mutaton=0.7)
    with pytest.raises(FkoptError, match="'rng' is set by fkopt"):
        fkopt.algorithm("scipy:dual_annealing", rng=3)
    with pytest.raises(FkoptError, match="unknown scipy adapter 'scipy:minimize'"):
        fkopt.algorithm("scipy:minimize")


def test_library_error_is_one_line_naming_the_adapter():
    p = Sphere(dim=2)
    with pytest.raises(FkoptError) as info:
        fkopt.solve(p, "scipy:differential_evolution", population=10, iterations=5,
                    params={"strategy": "no-such-strategy"})
    msg = str(info.value)
    assert "scipy:differential_evolution" in msg and "scipy 1." in msg and "\n" not in msg


def test_pymoo_and_niapy_names_and_params():
    pytest.importorskip("pymoo")
    pytest.importorskip("niapy")
    with pytest.raises(FkoptError, match="unknown pymoo adapter 'pymoo:XX'; allowed: pymoo:GA, pymoo:DE, pymoo:PSO"):
        fkopt.algorithm("pymoo:XX")
    with pytest.raises(FkoptError, match="'pymoo:DE' has no parameter 'nope'"):
        fkopt.algorithm("pymoo:DE", nope=1)
    with pytest.raises(FkoptError, match="unknown NiaPy algorithm 'niapy:Foo'; allowed: .*ArtificialBeeColonyAlgorithm"):
        fkopt.algorithm("niapy:Foo")
    with pytest.raises(FkoptError, match="'niapy:ArtificialBeeColonyAlgorithm' has no parameter 'limt'"):
        fkopt.algorithm("niapy:ArtificialBeeColonyAlgorithm", limt=5)
    a = fkopt.algorithm("pymoo:DE", CR=0.5)
    r = fkopt.solve(Sphere(dim=2), a, population=10, iterations=5, runs=1)
    assert r.params["CR"] == 0.5 and r.evaluations[0] == 60


def test_adapter_on_a_problem_with_cases_solves_each_case_as_alone():
    """A batched problem (one target per case): each row's run gets its own case's target and seed."""
    m = fkopt.mechanism("3-rps")
    p = fkopt.fk_problem(m, m.ik([[9, 13, 622], [0, 0, 500]]))
    both = fkopt.solve(p, "scipy:differential_evolution", population=10, iterations=20, runs=2, seed=[1, 2])
    alone = fkopt.solve(p.case(1), "scipy:differential_evolution", population=10, iterations=20, runs=2, seed=2)
    assert both.fitness.shape == (2, 2)
    np.testing.assert_array_equal(both.case(1).fitness, alone.fitness)
    np.testing.assert_array_equal(both.case(1).x, alone.x)
