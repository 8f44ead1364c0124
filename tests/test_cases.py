"""Problems with a case axis: one solve over cases x runs gives every case the numbers it gets alone."""
from functools import lru_cache

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import fkopt
from fkopt.errors import FkoptError
from fkopt.problems import BoxedProblem
from fkopt.numerics.streams import case_seed

M = fkopt.mechanism("3-rps")
POSES = np.array([[9.0, 13.0, 622.0], [-17.0, 8.0, 436.0], [4.0, -7.0, 509.0], [-13.0, -19.0, 574.0]])
JOINTS = M.ik(POSES)
SEEDS = (11, 2017, 5, 99)
ALGORITHMS = ("abc", "gabc", "pso", "aco", "pabc", "gabc+lm", "pso+lm", "nr", "lm", "dls")
BUDGET = dict(population=4, iterations=12, target=1e-3)
ARRAYS = ("x", "fitness", "history", "evaluation_history", "iterations_done")


@lru_cache(maxsize=None)
def alone(name: str, case: int, runs: int, stop: bool):
    """Case ``case`` solved on its own, single-target, with its seed."""
    return fkopt.solve(fkopt.fk_problem(M, JOINTS[case]), name, runs=runs, seed=SEEDS[case],
                       stop_at_target=stop, **BUDGET)


def assert_case_equals(batched, j: int, ref) -> None:
    one = batched.case(j)
    for name in ARRAYS:
        np.testing.assert_array_equal(getattr(one, name), getattr(ref, name), err_msg=name)
    assert one.extras.keys() == ref.extras.keys()
    for key in ref.extras:
        np.testing.assert_array_equal(one.extras[key], ref.extras[key], err_msg=key)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(ALGORITHMS),
       cases=st.lists(st.integers(0, len(POSES) - 1), min_size=1, max_size=4),
       runs=st.integers(1, 3), chunk=st.integers(1, 7), stop=st.booleans(), batch=st.booleans())
def test_a_case_is_the_same_alone_in_any_batch_and_any_chunks(name, cases, runs, chunk, stop, batch):
    problem = fkopt.fk_problem(M, JOINTS[cases])
    r = fkopt.solve(problem, name, runs=runs, seed=[SEEDS[c] for c in cases], stop_at_target=stop,
                    chunk_rows=chunk, batch=batch, **BUDGET)
    assert r.fitness.shape == (len(cases), runs) and r.x.shape == (len(cases), runs, 3)
    assert r.history.shape == (len(cases), runs, BUDGET["iterations"] + 1)
    for j, c in enumerate(cases):
        assert_case_equals(r, j, alone(name, c, runs, stop))


def test_one_int_seed_derives_a_seed_per_case():
    problem = fkopt.fk_problem(M, JOINTS)
    r = fkopt.solve(problem, "gabc", runs=2, seed=7, **BUDGET)
    assert r.seeds.tolist() == [case_seed(7, c) for c in range(len(POSES))]
    for c in (0, 3):
        ref = fkopt.solve(fkopt.fk_problem(M, JOINTS[c]), "gabc", runs=2, seed=case_seed(7, c), **BUDGET)
        assert_case_equals(r, c, ref)
        assert r.case(c).seed == case_seed(7, c)
    with pytest.raises(FkoptError, match="one integer per case"):
        fkopt.solve(problem, "gabc", seed=[1, 2], **BUDGET)


def test_ik_problem_with_cases_equals_each_pose_alone():
    arm = fkopt.mechanism("7dof-arm")
    rng = np.random.default_rng(4)
    q = arm.bounds[:, 0] + rng.random((3, 7)) * (arm.bounds[:, 1] - arm.bounds[:, 0])
    poses = arm.fk(q)
    for objective in ("paper", "geodesic"):
        problem = fkopt.ik_problem(arm, poses, objective=objective)
        assert problem.cases == 3
        np.testing.assert_allclose(problem.position_error(q[:, None, :]), 0.0, atol=1e-9)
        r = fkopt.solve(problem, "abc", population=6, iterations=10, runs=2, seed=[1, 2, 3], chunk_rows=4)
        for c in range(3):
            ref = fkopt.solve(fkopt.ik_problem(arm, poses[c], objective=objective), "abc", population=6,
                              iterations=10, runs=2, seed=c + 1)
            assert_case_equals(r, c, ref)


def test_result_success_message_and_single_case_shapes():
    r = fkopt.solve(fkopt.fk_problem(M, JOINTS), "gabc+lm", population=6, iterations=40, runs=3, seed=1,
                    target=1e-10)
    assert r.success.shape == (4, 3) and r.success.all()
    assert r.message.startswith("12 of 12 runs (4 cases x 3)")
    assert r.evaluations.shape == (4, 3) and r.iterations_to(1e-10).shape == (4, 3)
    assert r.best_run.shape == (4,) and r.x_history is None
    single = r.case(2)
    assert single.cases is None and single.fitness.shape == (3,) and isinstance(single.best_run, int)
    free = fkopt.solve(fkopt.fk_problem(M, JOINTS[0]), "abc", population=4, iterations=3, runs=2)
    assert free.success.all() and "no target" in free.message
    kept = fkopt.solve(fkopt.fk_problem(M, JOINTS), "abc", population=4, iterations=3, runs=2, x_history=True)
    assert kept.x_history.shape == (4, 2, 4, 3)


def test_local_methods_take_a_start_per_case_or_per_case_and_run():
    problem = fkopt.fk_problem(M, JOINTS)
    near = POSES + 0.5
    per_case = fkopt.solve(problem, "lm", population=1, iterations=30, runs=2, x0=near, x_history=True)
    np.testing.assert_array_equal(per_case.x_history[:, :, 0], np.repeat(near[:, None], 2, axis=1))
    assert np.abs(per_case.x - POSES[:, None]).max() < 1e-6
    starts = np.stack([near, near - 1.0], axis=1)            # (cases, runs, dim)
    per_row = fkopt.solve(problem, "nr", population=1, iterations=20, runs=2, x0=starts, x_history=True)
    np.testing.assert_array_equal(per_row.x_history[:, :, 0], starts)
    with pytest.raises(FkoptError, match="one per case"):
        fkopt.solve(problem, "lm", population=1, runs=2, x0=np.zeros((3, 3)))


def test_batch_too_large_for_memory_is_refused_before_allocating():
    problem = fkopt.fk_problem(M, np.repeat(JOINTS, 250, axis=0))       # 1000 cases
    with pytest.raises(FkoptError, match=r"needs about .* GiB of memory, more than fkopt's per-solve limit"):
        fkopt.solve(problem, "gabc", population=10, iterations=100_000, runs=1000)


def test_case_axis_input_errors():
    with pytest.raises(FkoptError, match=r"expected \(cases, 3\) values"):
        fkopt.fk_problem(M, np.zeros((2, 4)))
    with pytest.raises(FkoptError, match="case 1"):
        fkopt.fk_problem(M, np.array([[1.0, 2, 3], [np.nan, 1, 1]]))
    problem = fkopt.fk_problem(M, JOINTS)
    with pytest.raises(FkoptError, match="needs points shaped"):
        problem.fitness(np.zeros((3, 5, 3)))
    with pytest.raises(FkoptError, match="single target"):
        fkopt.fk_problem(M, JOINTS[0]).take([0])


def test_boxed_problem_searches_one_box_per_case():
    problem = fkopt.fk_problem(M, JOINTS)
    lo, hi = POSES - 2.0, POSES + 2.0
    boxed = BoxedProblem(problem, lo, hi)
    r = fkopt.solve(boxed, "gabc+lm", population=6, iterations=40, runs=2, seed=3)
    x = boxed.to_x(r.x)
    assert np.all((x >= lo[:, None] - 1e-9) & (x <= hi[:, None] + 1e-9))
    assert np.abs(x - POSES[:, None]).max() < 1e-6


def test_experiment_batches_cases_with_the_task_seeds():
    from fkopt.kinds.experiment.config import ExperimentConfig
    from fkopt.kinds.experiment.runner import run_experiment, task_seed
    cfg = ExperimentConfig(name="x", mechanism={"name": "3-rps"},
                           cases=[{"pose": dict(zip(M.pose_names, p))} for p in POSES[:3]],
                           algorithms=[{"name": "gabc"}, {"name": "pso", "label": "p"}],
                           population=4, iterations=12, runs=2, seed=9)
    er = run_experiment(cfg)
    assert [(r.case.index, r.spec.key) for r in er.own.solves] == [(c, a) for c in range(3) for a in ("gabc", "p")]
    for rec in er.own.solves:
        seed = task_seed(9, rec.case.index, rec.spec.key)
        ref = fkopt.solve(fkopt.fk_problem(M, rec.case.inputs), rec.spec.name, population=4, iterations=12,
                          runs=2, seed=seed)
        mine = er.record[(er.record["pose"] == rec.case.index) & (er.record["solver"] == rec.spec.key)]
        assert set(mine["task_seed"]) == {seed} and rec.result.seed == seed
        for name in ARRAYS:
            np.testing.assert_array_equal(getattr(rec.result, name), getattr(ref, name), err_msg=name)


def test_experiment_too_large_for_memory_fails_validation():
    from fkopt.kinds.experiment.config import ExperimentConfig
    from fkopt.kinds.experiment.runner import validate_experiment
    cfg = ExperimentConfig(name="huge", mechanism={"name": "3-rps"}, cases={"random": 2000, "seed": 1},
                           algorithms=[{"name": "gabc"}], iterations=100_000, runs=100)
    with pytest.raises(FkoptError, match=r"algorithms\[gabc\]: a batch of 200000 runs \(2000 cases x 100 runs\) of 100000 "
                       r"iterations needs about .* GiB of memory"):
        validate_experiment(cfg)
