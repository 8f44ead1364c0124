"""Workspace studies: config errors, executors give identical results, resume, statistics, tracking."""
import filecmp
import json
import os
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from fkopt.errors import FkoptError
from fkopt.kinds.study import run_study, study_from_dict
from fkopt.run.pipeline import load_any
from fkopt.kinds.study.runner import TASKS, plan_tasks, validate_study, work_folder
from fkopt.kinds.study.statistics import ecdf_table, holm, pairwise_tests

ROOT = Path(__file__).resolve().parents[1]
#: Files that must not depend on executor, jobs or resume (timing.csv does, by design).
DETERMINISTIC = ("summary.csv", "poses.csv", "runs.csv", "ecdf.csv", "stats.csv", "meta.json", "ecdf.png")


def small(**over):
    cfg = {
        "kind": "study", "name": "small", "title": "small study",
        "mechanism": {"name": "3-rps"},
        "poses": {"uniform": 6, "seed": 3},
        "algorithms": [{"name": "gabc"}, {"name": "lm", "start": "centre", "population": 1, "iterations": 30}],
        "population": 8, "iterations": 40, "runs": 3, "seed": 11, "threshold": 1e-8, "chunk": 2,
    }
    cfg.update(over)
    return study_from_dict(cfg)


def tracking_config(**over):
    cfg = {
        "kind": "study", "name": "track", "mode": "tracking", "mechanism": {"name": "3-rps"},
        "poses": {"waypoints": [{"alpha": -10, "beta": 0, "z": 500}, {"alpha": 10, "beta": 5, "z": 560}],
                  "points": 8},
        "algorithms": [
            {"name": "lm", "start": "centre", "population": 1, "iterations": 30},
            {"name": "lm", "label": "lm-cold", "start": "centre", "population": 1, "iterations": 30,
             "warm_start": False},
            {"name": "gabc", "population": 8, "iterations": 40},
        ],
        "runs": 2, "seed": 5, "threshold": 1e-10, "stop_at_threshold": True, "tracking": {"radius": 0.1},
    }
    cfg.update(over)
    return study_from_dict(cfg)


def same_files(a: Path, b: Path, names=DETERMINISTIC):
    for name in names:
        assert filecmp.cmp(a / name, b / name, shallow=False), f"{name} differs between {a} and {b}"


# -- config validation ------------------------------------------------------------------------------
@pytest.mark.parametrize("over, fragment", [
    ({"poses": {"uniform": 5, "grid": {"alpha": [-1, 1, 2]}}}, "exactly one of uniform, grid"),
    ({"poses": {"seed": 1}}, "exactly one of uniform, grid, waypoints, circle"),
    ({"poses": {"uniform": 0}}, "poses.uniform"),
    ({"poses": {"grid": {"alpha": [-1, 1, 3]}, "fixd": {"z": 500}}}, "poses.fixd: unknown field"),
    ({"poses": {"circle": {"centre": {"alpha": 0, "beta": 0, "z": 550}, "radius": 5, "plane": ["alpha", "alpha"]},
                "points": 8}}, "must differ"),
    ({"mode": "tracking"}, "mode tracking needs a trajectory"),
    ({"mode": "sweep"}, "mode"),
    ({"runs": 0}, "runs"),
    ({"threshold": -1}, "threshold"),
    ({"colour": "red"}, "colour: unknown field"),
    ({"algorithms": [{"name": "lm"}, {"name": "lm"}]}, "'lm' repeats"),
    ({"algorithms": [{"name": "lm", "start": "middle"}]}, "algorithms[0].start"),
])
def test_config_errors_name_the_field(over, fragment):
    with pytest.raises(FkoptError) as err:
        small(**over)
    assert fragment in str(err.value)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("over, fragment", [
    ({"poses": {"grid": {"alpha": [-1, 1, 3], "gamma": [0, 1, 2]}, "fixed": {"z": 500}}}, "unknown variable 'gamma'"),
    ({"poses": {"grid": {"alpha": [-1, 1, 3]}, "fixed": {"z": 500}}}, "missing beta"),
    ({"poses": {"grid": {"alpha": [-1, 1, 3], "beta": [0, 1, 2]}, "fixed": {"z": 900}}}, "outside the workspace bounds"),
    ({"poses": {"waypoints": [{"alpha": 0, "beta": 0, "z": 500}, {"alpha": 0, "beta": 0}], "points": 3}}, "missing z"),
    ({"algorithms": [{"name": "lm", "start": {"alpha": 0, "beta": 0, "z": 100}}]}, "outside the workspace bounds"),
    ({"algorithms": [{"name": "warp"}]}, "unknown algorithm 'warp'"),
    ({"mechanism": {"name": "9-rps"}}, "unknown mechanism"),
])
def test_semantic_errors_fail_before_any_work(over, fragment):
    with pytest.raises(FkoptError) as err:
        validate_study(small(**over))
    assert fragment in str(err.value)


def test_load_any_dispatches_on_kind(tmp_path):
    study = tmp_path / "s.yaml"
    study.write_text(yaml.safe_dump(small().model_dump(mode="json")))
    assert type(load_any(study)).__name__ == "StudyConfig"
    experiment = ROOT / "configs" / "mao2017" / "tab6.yaml"
    assert type(load_any(experiment)).__name__ == "ExperimentConfig"
    bad = tmp_path / "b.yaml"
    bad.write_text("kind: survey\nname: x\n")
    with pytest.raises(FkoptError, match="kind: 'survey' unknown; allowed: study"):
        load_any(bad)


@pytest.mark.parametrize("path", sorted((ROOT / "configs" / "studies").glob("*.yaml")), ids=lambda p: p.name)
def test_stored_study_configs_validate(path):
    config = load_any(path)
    mech, poses = validate_study(config)
    assert config.paper == "studies" and config.kind == "study"
    assert len(plan_tasks(config, len(poses))) >= len(config.algorithms)


def test_cli_errors_are_one_line(tmp_path, cli):
    study = tmp_path / "s.yaml"
    study.write_text(yaml.safe_dump(small().model_dump(mode="json")))
    for args, fragment in [(["study", study, "--jobs", "0"], "--jobs: must be at least 1"),
                           (["study", study, "--executor", "slurm"], "--executor: 'slurm' unknown; allowed: local, dask"),
                           (["study", study, "--scheduler", "tcp://x:1"], "only used with --executor dask"),
                           (["study", tmp_path / "missing.yaml"], "cannot read"),
                           (["run", study, "--jobs", "0"], "--jobs: must be at least 1")]:
        code, _, err = cli(*args)
        err = err.strip()
        assert code == 2
        assert len(err.splitlines()) == 1 and err.startswith("fkopt: error: ") and fragment in err, err


# -- executors: identical results ------------------------------------------------------------------
def test_jobs_1_and_2_and_dask_give_identical_results(tmp_path):
    config = small()
    one = run_study(config, tmp_path / "one", jobs=1)
    two = run_study(config, tmp_path / "two", jobs=2)
    assert len(one.computed) == len(two.computed) == len(plan_tasks(config, 6)) == 6
    same_files(one.folder, two.folder)
    # the workers really were other processes
    pids = {json.loads(p.read_text())["pid"] for p in (two.folder / TASKS).glob("a*.json")}
    assert os.getpid() not in pids
    try:
        from dask.distributed import LocalCluster
    except ImportError:
        pytest.skip("dask.distributed not installed (pip install 'fkopt[dask]')")
    # an existing cluster reached through its scheduler address, as with --scheduler (in-process
    # workers keep the test short; the local pool above already ran tasks in other processes)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
        three = run_study(config, tmp_path / "dask", executor="dask", scheduler=cluster.scheduler_address)
    same_files(one.folder, three.folder)


def test_chunk_size_does_not_change_numbers(tmp_path):
    a = run_study(small(chunk=1), tmp_path / "a")
    b = run_study(small(chunk=6), tmp_path / "b")
    for name in ("summary.csv", "runs.csv", "stats.csv", "ecdf.csv"):
        assert filecmp.cmp(a.folder / name, b.folder / name, shallow=False), name


# -- resume ----------------------------------------------------------------------------------------
class Interrupt(KeyboardInterrupt):
    pass


def test_resume_after_interruption_matches_uninterrupted_run(tmp_path):
    config = small()
    full = run_study(config, tmp_path / "full")

    def stop_after(n):
        def progress(label, done, total):
            if done >= n:
                raise Interrupt
        return progress

    with pytest.raises(Interrupt):
        run_study(config, tmp_path / "cut", progress=stop_after(4))
    folder = tmp_path / "cut" / "studies" / "small"
    work = work_folder(tmp_path / "cut", config)         # unfinished: tasks kept beside the result
    files = sorted((work / TASKS).glob("a*.json"))
    assert len(files) == 4 and not folder.exists()
    assert not list((work / TASKS).glob(".*"))         # no half-written temporary files
    files[1].unlink()                                   # a task lost, e.g. never written
    kept = {p.name: p.stat().st_mtime_ns for p in files if p.exists()}
    resumed = run_study(config, tmp_path / "cut", resume=True)
    assert len(resumed.computed) == 6 - 3               # the 3 kept tasks were not recomputed
    assert not set(resumed.computed) & {n.removesuffix(".json") for n in kept}
    kept_now = {p.name: p.stat().st_mtime_ns for p in (folder / TASKS).glob("a*.json") if p.name in kept}
    assert kept_now == kept                             # moved into the finished folder, not rewritten
    assert not work.exists()
    same_files(full.folder, resumed.folder)

    # a finished study: delete the merged output and two task files, resume recomputes only those
    for name in ("summary.csv", "meta.json"):
        (folder / name).unlink()
    for p in sorted((folder / TASKS).glob("a01-*.json"))[:2]:
        p.unlink()
    again = run_study(config, tmp_path / "cut", resume=True)
    assert sorted(again.computed) == ["a01-lm-c00000", "a01-lm-c00001"]
    same_files(full.folder, again.folder)


def test_resume_refuses_tasks_of_a_changed_config(tmp_path):
    run_study(small(), tmp_path)
    with pytest.raises(FkoptError, match="config or pose sets changed"):
        run_study(small(seed=12), tmp_path, resume=True)
    # without --resume it starts afresh
    res = run_study(small(seed=12), tmp_path)
    assert len(res.computed) == 6


def test_fkopt_run_runs_a_study_through_the_same_pipeline(tmp_path, cli):
    """One pipeline: ``fkopt run`` on a study file is ``fkopt study`` (same bytes, same options)."""
    study = tmp_path / "s.yaml"
    study.write_text(yaml.safe_dump(small(poses={"uniform": 4, "seed": 1}).model_dump(mode="json")))
    assert cli("study", study, "--out", tmp_path / "a", "-q")[0] == 0
    code, _, err = cli("run", study, "--out", tmp_path / "b", "-q", "--jobs", "2")
    assert code == 0, err
    same_files(tmp_path / "a" / "studies" / "small", tmp_path / "b" / "studies" / "small")


def test_cli_study_and_resume(tmp_path, cli):
    study = tmp_path / "s.yaml"
    study.write_text(yaml.safe_dump(small(poses={"uniform": 2, "seed": 1}).model_dump(mode="json")))
    out = tmp_path / "res"
    code, _, err = cli("study", study, "--out", out, "--quiet")
    assert code == 0, err
    folder = out / "studies" / "small"
    assert (folder / "meta.json").exists() and (folder / "summary.csv").exists()
    code, stdout, err = cli("study", study, "--out", out, "--resume")
    assert code == 0, err
    assert "2 finished task(s) reused, 0 computed" in stdout


def test_cli_ctrl_c_keeps_finished_tasks(tmp_path, cli, monkeypatch):
    import fkopt.kinds.study.runner as runner
    study = tmp_path / "s.yaml"
    study.write_text(yaml.safe_dump(small().model_dump(mode="json")))
    real, calls = runner.run_task, []

    def interrupted_on_third(payload):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(payload)
    monkeypatch.setattr(runner, "run_task", interrupted_on_third)
    code, _, err = cli("study", study, "--out", tmp_path, "--quiet")
    assert code == 130 and "interrupted" in err and "--resume" in err
    assert len(list((work_folder(tmp_path, small()) / TASKS).glob("a*.json"))) == 2
    monkeypatch.setattr(runner, "run_task", real)
    code, _, err = cli("study", study, "--out", tmp_path, "--quiet", "--resume")
    assert code == 0 and (tmp_path / "studies" / "small" / "meta.json").exists()


# -- statistics ------------------------------------------------------------------------------------
def test_holm_matches_hand_computation():
    # sorted: 0.005*4 = 0.02, 0.01*3 = 0.03, 0.03*2 = 0.06, 0.04*1 = 0.04 -> max(0.06, 0.04) = 0.06
    np.testing.assert_allclose(holm([0.01, 0.04, 0.03, 0.005]), [0.03, 0.06, 0.06, 0.02])
    np.testing.assert_allclose(holm([0.5, 0.6]), [1.0, 1.0])     # capped at 1, monotone
    np.testing.assert_allclose(holm([0.2]), [0.2])


def test_pairwise_tests_against_scipy():
    from scipy.stats import mannwhitneyu
    a, b = np.array([1.0, 2, 3, 4, 5]), np.array([6.0, 7, 8, 9, np.nan])   # NaN: never solved
    df = pairwise_tests({"evaluations_to_threshold": {"a": a, "b": b, "c": a + 0.5}})
    row = df[(df.algorithm_a == "a") & (df.algorithm_b == "b")].iloc[0]
    ref = mannwhitneyu(a, np.array([6.0, 7, 8, 9, np.inf]), alternative="two-sided")
    assert row.U == ref.statistic and row.p_value == pytest.approx(ref.pvalue)
    assert row.prob_a_lower == 1.0
    np.testing.assert_allclose(df.p_holm, holm(df.p_value))
    tied = pairwise_tests({"final_fitness": {"x": np.zeros(4), "y": np.zeros(4)}}).iloc[0]
    assert tied.p_value == 1.0 and tied.better == ""


@settings(max_examples=40, deadline=None)
@given(st.lists(st.one_of(st.none(), st.integers(1, 10_000)), min_size=1, max_size=60))
def test_ecdf_is_monotone(values):
    ev = np.array([np.nan if v is None else float(v) for v in values])
    df = ecdf_table({"a": ev})
    solved = int((~np.isnan(ev)).sum())
    if solved == 0:
        assert df.fraction.tolist() == [0.0]
        return
    assert np.all(np.diff(df.evaluations) > 0)
    assert np.all(np.diff(df.fraction) > 0)
    assert 0 < df.fraction.iloc[0] and df.fraction.iloc[-1] == pytest.approx(solved / ev.size)


# -- tracking --------------------------------------------------------------------------------------
def test_tracking_warm_starts_from_previous_solution(tmp_path):
    config = tracking_config()
    res = run_study(config, tmp_path)
    runs = pd.read_csv(res.folder / "runs.csv")
    names = ("alpha", "beta", "z")
    centre = res.own.mechanism.bounds.mean(axis=1)
    width = res.own.mechanism.bounds[:, 1] - res.own.mechanism.bounds[:, 0]
    for algo in ("lm", "gabc"):
        d = runs[runs.algorithm == algo].sort_values(["run", "pose"])
        for _, g in d.groupby("run"):
            start = g[[f"start_{n}" for n in names]].to_numpy()[1:]
            prev = g[[f"x_{n}" for n in names]].to_numpy()[:-1]
            np.testing.assert_array_equal(start, prev)        # x0 = previous step's solution
            if algo == "gabc":                                # the swarm searched a box around it
                x = g[[f"x_{n}" for n in names]].to_numpy()[1:]
                assert np.all(np.abs(x - prev) <= 0.1 * width + 1e-9)
    cold = runs[runs.algorithm == "lm-cold"][[f"start_{n}" for n in names]].to_numpy()
    np.testing.assert_array_equal(cold, np.broadcast_to(centre, cold.shape))
    track = pd.read_csv(res.folder / "tracking.csv")
    assert track[track.algorithm == "lm"].warm_start.tolist() == [False] + [True] * 7
    assert not track[track.algorithm == "lm-cold"].warm_start.any()
    s = pd.read_csv(res.folder / "summary.csv").set_index("algorithm")
    assert s.loc["lm", "success_rate"] == 1.0
    assert s.loc["lm", "mean_evaluations"] < s.loc["lm-cold", "mean_evaluations"]   # warm start pays
    timing = pd.read_csv(res.folder / "tracking_timing.csv")
    assert len(timing) == 3 * 8 and (timing.ms_per_run > 0).all()
    assert "ms_per_run" not in track.columns and "time" not in " ".join(track.columns)


TWO_TRAJECTORIES = [
    {"circle": {"centre": {"alpha": 0, "beta": 0, "z": 550}, "radius": [8, 4], "plane": ["alpha", "beta"]},
     "points": 6},
    {"waypoints": [{"alpha": -10, "beta": 0, "z": 500}, {"alpha": 10, "beta": 5, "z": 560}], "points": 4},
]


def test_tracking_batches_trajectories_each_as_if_alone():
    """Step t of every trajectory is one solve; each trajectory's numbers equal those of a solve of
    that trajectory alone (same pose indices, hence the same seeds), for local methods and warm swarms."""
    from fkopt.kinds.study.runner import Task, _track, task_rows
    config = tracking_config(poses=TWO_TRAJECTORIES)
    mech, poses = validate_study(config)
    assert poses.segments == ((0, 6), (6, 10))
    assert poses.step.tolist() == [0, 1, 2, 3, 4, 5, 0, 1, 2, 3]
    for a, spec in enumerate(config.algorithms):
        task = Task(a, spec.key, 0, 0, len(poses))
        both = pd.DataFrame(task_rows(config, mech, poses, spec, _track(config, mech, poses, spec, task))[0])
        for seg in poses.segments:
            one = replace(poses, segments=(seg,))
            alone = pd.DataFrame(task_rows(config, mech, one, spec, _track(config, mech, one, spec, task))[0])
            mine = both[both["pose"].between(seg[0], seg[1] - 1)].reset_index(drop=True)
            assert alone["pose"].tolist() == [i for i in range(*seg) for _ in range(config.runs)]
            assert {c for c in alone if c.startswith("start_")}                    # tracking: its start points
            pd.testing.assert_frame_equal(mine, alone, check_exact=True, obj=f"{spec.key} {seg}")


def test_tracking_several_trajectories_report(tmp_path):
    res = run_study(tracking_config(poses=TWO_TRAJECTORIES), tmp_path)
    track = pd.read_csv(res.folder / "tracking.csv")
    lm = track[track.algorithm == "lm"]
    assert lm.trajectory.tolist() == [0] * 6 + [1] * 4     # indices count from 0 (fkopt.run.record)
    assert lm.step.tolist() == [0, 1, 2, 3, 4, 5, 0, 1, 2, 3]
    assert lm.warm_start.tolist() == [False] + [True] * 5 + [False] + [True] * 3   # each starts cold
    assert (res.folder / "tracking.png").exists()
    runs = pd.read_csv(res.folder / "runs.csv")
    first = runs[(runs.algorithm == "lm") & (runs.pose == 6)]     # trajectory 1, step 0: from the centre
    centre = res.own.mechanism.bounds.mean(axis=1)
    np.testing.assert_array_equal(first[["start_alpha", "start_beta", "start_z"]].to_numpy(),
                                  np.broadcast_to(centre, (2, 3)))


@pytest.mark.parametrize("poses, mode, fragment", [
    (TWO_TRAJECTORIES, "independent", "a list of trajectories needs mode: tracking"),
    ([{"uniform": 5}], "tracking", "poses[0]: a trajectory needs exactly one of waypoints, circle"),
    ([TWO_TRAJECTORIES[0], {"waypoints": [{"alpha": 0, "beta": 0, "z": 500}], "points": 3}], "tracking",
     "poses[1].waypoints"),
    ([], "tracking", "poses: 1 to 1000 trajectories"),
])
def test_trajectory_list_errors(poses, mode, fragment):
    with pytest.raises(FkoptError) as err:
        small(poses=poses, mode=mode)
    assert fragment in str(err.value) and "\n" not in str(err.value)


# -- grid heat map, report, check ------------------------------------------------------------------
def test_stored_configs_run_small_and_feed_report_check_claims(tmp_path):
    from fkopt.reproduce import PAPERS, studies
    from fkopt.reproduce.check import check_experiment
    from fkopt.reproduce.report import build_report
    from fkopt.reproduce.store import Store
    assert PAPERS["studies"] == "fkopt.reproduce.studies"
    smaller = {"3rps_workspace.yaml": {"poses": {"uniform": 4, "seed": 1}, "runs": 2, "iterations": 150},
               "3rps_slice.yaml": {"poses": {"grid": {"alpha": [-20, 20, 3], "beta": [-20, 20, 3]},
                                             "fixed": {"z": 550}}, "runs": 2},
               "6sps_tracking.yaml": {"runs": 2}}
    tracking = yaml.safe_load((ROOT / "configs" / "studies" / "6sps_tracking.yaml").read_text())["poses"]
    smaller["6sps_tracking.yaml"]["poses"] = [{**t, "points": 4} for t in tracking]     # both, 4 steps each
    for name, over in smaller.items():
        data = yaml.safe_load((ROOT / "configs" / "studies" / name).read_text())
        data.update(over)
        run_study(study_from_dict(data, name), tmp_path, source=f"configs/studies/{name}")
    store = Store(tmp_path)
    slice_ = store.get("studies", "3rps_slice")
    assert slice_.has("heatmap.png") and len(slice_.table("heatmap")) == 9 * 3
    track = store.get("studies", "6sps_tracking")
    assert track.has("tracking.png") and track.has("tracking_time.png")
    claims = studies.claims(store)
    assert len(claims) >= 8 and all(c.verdict in ("held", "not held", "not checkable") for c in claims)
    assert studies.timing_claims(store)
    report, timing, index = build_report(tmp_path)
    assert "Pairwise Wilcoxon rank-sum tests" in report and "heatmap.png" in report
    assert "tracking_time.png" not in report and "tracking_time.png" in timing
    assert set(index.experiment) == {"3rps_workspace", "3rps_slice", "6sps_tracking"}
    assert check_experiment(slice_) == []
    # check has teeth: a changed threshold in the recorded config is detected
    meta = json.loads((slice_.folder / "meta.json").read_text())
    meta["config"]["threshold"] = 1e-12
    (slice_.folder / "meta.json").write_text(json.dumps(meta))
    bad = check_experiment(store.get("studies", "3rps_slice"))
    assert bad and bad[0].file == "summary.csv"


def test_reproduce_runs_study_configs(tmp_path, cli):
    configs = tmp_path / "configs" / "studies"
    configs.mkdir(parents=True)
    (configs / "s.yaml").write_text(yaml.safe_dump(small(poses={"uniform": 2, "seed": 1}).model_dump(mode="json")))
    out = tmp_path / "results"
    code, _, err = cli("reproduce", "--configs", tmp_path / "configs", "--out", out, "--quiet")
    assert code == 0, err
    assert (out / "studies" / "small" / "meta.json").exists()
    assert "### small study" in (out / "REPORT.md").read_text()
