"""The one run record (fkopt.run.record): its schema, its writers, every kind producing it, one
numbering (poses from 0, the index the seed rule takes) and timing runs as planned tasks."""
import numpy as np
import pandas as pd
import pytest

from fkopt.run import record
from fkopt.kinds.experiment.config import experiment_from_dict
from fkopt.run.pipeline import run_in_memory
from fkopt.kinds.experiment.runner import experiment_plan, task_seed
from fkopt.run.tasks import run_tasks
from fkopt.run.timing import sample_plan


def tiny_experiment(**over):
    data = {"name": "tiny", "mechanism": {"name": "3-rps"},
            "cases": [{"pose": {"alpha": 9, "beta": 13, "z": 622}}, {"pose": {"alpha": -5, "beta": 4, "z": 560}}],
            "algorithms": [{"name": "gabc"}, {"name": "pso"}], "population": 6, "iterations": 15, "runs": 3,
            "seed": 4, "threshold": 1e-6}
    data.update(over)
    return experiment_from_dict(data, "tiny")


# -- schema ----------------------------------------------------------------------------------------
def test_a_column_outside_the_schema_is_refused_by_name():
    with pytest.raises(ValueError, match="'fitnes'"):
        record.run_record("experiment", {"run": [0, 1], "fitnes": [1.0, 2.0]})
    with pytest.raises(ValueError, match="kind"):
        record.run_record("paper", {"run": [0]})


def test_columns_come_in_schema_order_with_their_dtypes():
    df = record.run_record("study", {"x_b": [1, 2], "x_a": [3, 4], "evaluations": [10.0, 12.0], "pose": [0, 1],
                                     "solver": "lm", "final_fitness": [1, 2], "task_seed": 7})
    # a family keeps the order given (the unknowns' order), fixed columns go where the schema says
    assert list(df.columns) == ["kind", "pose", "solver", "task_seed", "final_fitness", "evaluations", "x_b", "x_a"]
    assert df["evaluations"].dtype == np.int64 and df["pose"].dtype == np.int64
    assert df["final_fitness"].dtype == np.float64 and df["x_b"].dtype == np.float64
    assert df["kind"].tolist() == ["study", "study"] and df["task_seed"].tolist() == [7, 7]


def test_runs_csv_leaves_out_what_the_folder_fixes_and_keeps_each_kinds_names():
    cols = {"problem": "p", "case": "case-1", "pose": [0, 0], "solver": "gabc", "run": [0, 1], "task_seed": 3,
            "final_fitness": [0.5, 0.25], "evaluations": [5, 6]}
    exp = record.runs_table(record.run_record("experiment", cols))
    assert list(exp.columns) == ["case", "algorithm", "run", "task_seed", "final_fitness", "evaluations"]
    suite = record.runs_table(record.run_record("suite", {k: v for k, v in cols.items() if k != "case"}))
    assert list(suite.columns) == ["problem", "pose", "solver", "run", "final_fitness", "evaluations"]


def test_summary_is_the_statistics_of_the_records_runs():
    f = np.array([1e-3, 1e-9, 2e-9, 5.0, 1e-12, 3e-7])
    rec = record.run_record("experiment", {
        "case": ["a"] * 3 + ["b"] * 3, "solver": "gabc", "run": [0, 1, 2] * 2, "final_fitness": f,
        "evaluations": [10, 20, 30, 40, 50, 60], "iterations_to_threshold": [np.nan, 4, 6, np.nan, 2, np.nan],
        "evaluations_to_threshold": [np.nan, 40, 60, np.nan, 20, np.nan]})
    settings = {"gabc": {"method": "gabc", "population": 10, "iterations": 50, "runs": 3, "printed": {"printed_x": 1}}}
    s = record.summary_table(rec, settings, 1e-6)
    assert s["case"].tolist() == ["a", "b"] and s.columns[-1] == "printed_x"
    a = s.iloc[0]
    assert a.mean_fitness == np.mean(f[:3]) and a.std_fitness == np.std(f[:3], ddof=1)
    assert a.success_rate == 2 / 3 and a.median_iterations_to_threshold == 5 and a.mean_evaluations == 20
    assert s.iloc[1].median_evaluations_to_threshold == 20 and s.iloc[1].worst_fitness == 5.0


def test_timing_prefers_runs_timed_alone_and_keeps_the_batch_beside():
    t = pd.concat([
        record.timing_record("experiment", {"case": "a", "solver": "s", "run": [0, 1, 2], "runs": 1,
                                            "seconds": [0.010, 0.020, 0.030], "mode": record.ALONE}),
        record.timing_record("experiment", {"case": "a", "solver": "s", "run": -1, "runs": 4, "seconds": 0.004,
                                            "mode": record.BATCH}),
        record.timing_record("experiment", {"case": "b", "solver": "s", "run": -1, "runs": 2, "seconds": 0.5,
                                            "mode": record.BATCH})], ignore_index=True)
    settings = {("a", "s"): {"runs": 3, "total_s": 1.0}, ("b", "s"): {"runs": 2, "total_s": 0.5}}
    table = record.timing_table(t, settings, names={"solver": "algorithm"})
    a, b = table.iloc[0], table.iloc[1]
    assert (a.timed_runs, a.median_ms_per_run, a.amortised_ms_per_run) == (3, 20.0, 1.0)
    assert (b.timed_runs, b.median_ms_per_run) == (2, 250.0) and "algorithm" in table.columns
    assert record.timing_table(t, settings, timed_alone=True)["case"].tolist() == ["a"]
    runs = record.timing_runs_table(t, names={"solver": "algorithm"})
    assert runs.columns.tolist() == ["case", "algorithm", "run", "ms"] and runs.ms.tolist() == [10.0, 20.0, 30.0]


# -- every kind ------------------------------------------------------------------------------------
def _conforms(df: pd.DataFrame, kind: str) -> None:
    assert (df["kind"] == kind).all()
    assert all(record._place(c) >= 0 for c in df.columns)
    assert [record._place(c) for c in df.columns] == sorted(record._place(c) for c in df.columns)


def test_an_experiment_record_is_its_runs_csv_and_its_seeds():
    config = tiny_experiment()
    er = run_in_memory(config, timing=False)
    _conforms(er.record, "experiment")
    assert len(er.record) == 2 * 2 * 3                        # cases x algorithms x runs
    pd.testing.assert_frame_equal(record.runs_table(er.record),
                                  er.record.drop(columns=["kind", "problem", "pose"]).rename(columns={"solver": "algorithm"}))
    seeds = {task_seed(config.seed, p, s) for p, s in zip(er.record.pose, er.record.solver)}
    assert seeds == set(er.record.task_seed) and sorted(set(er.record.pose)) == [0, 1]


def test_a_study_and_a_suite_number_poses_from_0_as_their_seeds_do(tmp_path):
    from fkopt.kinds.study import study_from_dict
    study = study_from_dict({"kind": "study", "name": "s", "mechanism": {"name": "3-rps"},
                             "poses": {"uniform": 3, "seed": 3}, "algorithms": [{"name": "lm", "start": "centre",
                                                                              "population": 1, "iterations": 10}],
                             "runs": 2, "seed": 11, "threshold": 1e-8, "chunk": 2})
    sr = run_in_memory(study, timing=False)
    _conforms(sr.record, "study")
    assert sorted(set(sr.record.pose)) == [0, 1, 2]
    assert all(seed == task_seed(11, p, "lm") for p, seed in zip(sr.record.pose, sr.record.task_seed))
    from test_kinbench import tiny
    from fkopt.run.pipeline import load_any
    suite = load_any(tiny(tmp_path, solvers=[{"name": "lm"}], poses=2, runs=1))
    res = run_in_memory(suite)
    _conforms(res.record, "suite")
    row = res.record.iloc[-1]
    assert row.pose in (0, 1) and row.task_seed == task_seed(suite.seed, row.pose, f"{row.problem}/{row.set}/lm")
    assert "task_seed" not in record.runs_table(res.record).columns


# -- timing as planned tasks ----------------------------------------------------------------------
def test_the_timing_sample_is_planned_tasks_run_after_every_solve():
    config = tiny_experiment()
    plan = experiment_plan(config)
    cases, per = sample_plan(2, config.runs)
    assert [t.id for t in plan.tasks] == ["a00", "a01"] and [t.id for t in plan.timed] == ["t00", "t01"][:cases]
    assert experiment_plan(config, timing=False).timed == []      # fkopt check: no timings planned
    seen = []
    ran = run_tasks(plan, progress=lambda label, done, total: seen.append((label, done, total)))
    assert [s[2] for s in seen] == [4] * 4 and [s[0] for s in seen][2:] == [t.label for t in plan.timed]
    t00 = ran.records["t00"]                   # rows of the timing record: per algorithm its runs timed alone
    assert t00["solver"] == [a.key for a in config.algorithms for _ in range(per)] and set(t00["mode"]) == {"alone"}
    # a record computed elsewhere for a timing task is never taken: timings are measured by this run
    ran2 = run_tasks(plan, done={"t00": "stale", **{t.id: ran.records[t.id] for t in plan.tasks}})
    assert ran2.records["t00"] != "stale" and ran2.computed == ["t00", "t01"][:cases]
