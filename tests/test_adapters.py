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


# -- per-point libraries: the counter's single-point path and runs in lockstep -------------------
def _drive(counter, points, single: bool):
    """Feed ``points`` one at a time until the counter stops the run; (values, stopped at)."""
    out = []
    for i, x in enumerate(points):
        try:
            out.append(counter.point(x) if single else float(counter.batch(x[None, :])[0]))
        except Exception as err:
            assert type(err).__name__ == "_Stop"
            return out, i
    return out, None


class Scripted:
    """A 2-D problem whose fitness is the first coordinate (NaN and inf included)."""
    dim = 2
    bounds = np.array([[-1e9, 1e9], [-1e9, 1e9]])

    def __init__(self):
        self.points = 0

    def fitness(self, x):
        x = np.asarray(x, dtype=float)
        self.points += int(np.prod(x.shape[:-1]))
        return x[..., 0].copy()


@pytest.mark.parametrize("budget,target,stop", [(9, None, False), (30, None, False), (30, 0.5, True),
                                                (30, -5.0, True), (4, 2.0, True)])
def test_counter_point_counts_and_traces_exactly_as_a_batch_of_one(budget, target, stop):
    values = [np.inf, np.nan, 7.0, 7.0, 3.0, np.nan, 5.0, 1.0, 0.25, 2.0, -np.inf, 0.1, -1.0]
    points = [np.array([v, float(i)]) for i, v in enumerate(values * 2)]
    runs = []
    for single in (True, False):
        p = Scripted()
        c = Counter(p, budget, target, stop)
        got, at = _drive(c, points, single)
        tr = c.trace()
        runs.append((got, at, c.n, c.best, p.points, tr.evals.tolist(), tr.f.tolist(), tr.x.tolist(), tr.used))
    assert runs[0] == runs[1] or str(runs[0]) == str(runs[1])     # NaN-free repr equality
    got, at, n, best, points_evaluated, evals, f, x, used = runs[0]
    assert n == points_evaluated == used <= budget and evals[0] == 1


def test_counter_point_keeps_its_own_copy_of_the_point():
    p = Scripted()
    c = Counter(p, 10)
    x = np.array([3.0, 1.0])
    c.point(x)
    x[0] = -100.0                                   # a library reusing its array
    assert c.trace().x.tolist() == [[3.0, 1.0]]


def _niapy_names():
    pytest.importorskip("niapy")
    return ["niapy:DifferentialEvolution", "niapy:ArtificialBeeColonyAlgorithm", "niapy:ParticleSwarmAlgorithm"]


@pytest.mark.parametrize("cases", [True, False])
def test_niapy_runs_in_lockstep_give_each_run_alone_numbers_and_counts(cases, monkeypatch):
    """Lockstep batches the runs' single-point calls; every number and count is the one of the
    runs evaluated one point after the other, run after run (and stopping at the target or at
    the budget works per run)."""
    from fkopt.adapters import adapter_class
    from fkopt.adapters import base
    m = fkopt.mechanism("3-rps")
    rng = np.random.default_rng(7)
    poses = m.bounds[:, 0] + rng.random((3, 3)) * np.ptp(m.bounds, axis=1)
    problem = fkopt.fk_problem(m, m.ik(poses)) if cases else fkopt.fk_problem(m, m.ik(poses[0]))
    monkeypatch.setattr(base, "LOCKSTEP_RUNS", 4)  # several groups, one of them short
    kw = dict(population=10, iterations=30, runs=3, seed=[3, 4, 5] if cases else 3, target=1e-3,
              stop_at_target=True)
    real = base.run_lockstep
    for name in _niapy_names():
        cls = adapter_class(*name.split(":"))
        assert cls.per_point
        calls = []
        monkeypatch.setattr(base, "run_lockstep", lambda *a: calls.append(1) or real(*a))
        together = fkopt.solve(problem, name, **kw)
        assert calls, "lockstep was not used"
        monkeypatch.setattr(cls, "per_point", False)           # one run after the other, point by point
        alone = fkopt.solve(problem, name, **kw)
        monkeypatch.setattr(cls, "per_point", True)
        for field in ("history", "x", "evaluations", "fitness", "evaluation_history", "iterations_done"):
            np.testing.assert_array_equal(getattr(together, field), getattr(alone, field), err_msg=f"{name} {field}")
        assert np.all(together.evaluations <= 10 * 31)


def test_lockstep_counts_every_point_once_and_passes_errors_on():
    pytest.importorskip("niapy")
    p = CountingSphere(dim=3)
    r = fkopt.solve(p, "niapy:DifferentialEvolution", population=8, iterations=12, runs=5, seed=1,
                    params={"evaluations": 77})
    assert p.points == r.evaluations.sum() == 5 * 77

    class Broken(Sphere):
        def fitness(self, x):
            if np.asarray(x).shape[0] > 1:         # fails on the first batched call
                raise ValueError("no batch")
            return super().fitness(x)
    with pytest.raises(FkoptError, match="niapy:DifferentialEvolution.*ValueError: no batch"):
        fkopt.solve(Broken(dim=2), "niapy:DifferentialEvolution", population=8, iterations=5, runs=3, seed=1)


def test_batched_fitness_of_every_kinbench_problem_is_that_of_each_point_alone():
    """What lockstep relies on: a point's fitness does not depend on the batch it is in."""
    from pathlib import Path
    from fkopt.kinds.experiment.runner import make_problem
    from fkopt.kinbench.config import load_suite
    from fkopt.kinbench.posesets import problem_mechanism, targets_of
    config = load_suite(Path(__file__).resolve().parents[1] / "configs" / "suites" / "kinbench-v2.yaml")
    rng = np.random.default_rng(11)
    for prob in config.problems:
        mech, cfg = problem_mechanism(prob, config._folder)
        truth = mech.bounds[:, 0] + rng.random((5, len(mech.bounds))) * np.ptp(mech.bounds, axis=1)
        problem = make_problem(cfg, mech, targets_of(mech, truth))
        x = mech.bounds[:, 0] + rng.random((5, len(mech.bounds))) * np.ptp(mech.bounds, axis=1)
        rows = [4, 0, 2]
        together = problem.take(rows).fitness(x[rows][:, None, :])[:, 0]
        alone = [float(problem.case(r).fitness(x[r][None, :])[0]) for r in rows]
        assert together.tolist() == alone, prob.name
