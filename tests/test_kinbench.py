"""kinbench: suite configs, frozen pose sets, COCO measures, leaderboard files, plug-ins."""
import hashlib
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from fkopt.errors import FkoptError
from fkopt.run.pipeline import from_dict, load_any, run_config
from fkopt.kinbench import measures as M
from fkopt.kinbench.config import load_suite
from fkopt.kinbench.posesets import (BOUNDARY_SHARE, condition_numbers, generate, load_pose_sets,
                                     problem_mechanism)
from fkopt.kinbench.budget import at_budget, target_column

ROOT = Path(__file__).resolve().parents[1]
SUITES = ROOT / "configs" / "suites"
SUITE = SUITES / "kinbench.yaml"
PY = sys.executable


def tiny(tmp_path, **over) -> Path:
    """A small suite beside a copy of the frozen pose sets (the folder the YAML names)."""
    shutil.copytree(SUITES / "kinbench-v1", tmp_path / "kinbench-v1")
    data = yaml.safe_load(SUITE.read_text())
    data.update(name="tiny", problems=[p for p in data["problems"] if p["name"] in ("mao2017-3rps", "wu2015-3ppr")],
                solvers=[{"name": "pso"}, {"name": "lm"}], poses=2, runs=2, budget_per_dim=100, bootstrap=200,
                quick=None)
    data.update(over)
    path = tmp_path / "tiny.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def cli(*args, cwd=None):
    return subprocess.run([PY, "-m", "fkopt.cli", *map(str, args)], capture_output=True, text=True, cwd=cwd,
                          env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})


# -- config -------------------------------------------------------------------------------------
def test_the_suite_file_and_its_quick_tier_validate():
    cfg = load_suite(SUITE)
    q = cfg.quick_tier()
    assert q.name == "kinbench-quick" and q.quick is None and q.check == "ci"
    assert {s.key for s in q.solvers} < {s.key for s in cfg.solvers} and q.poses < cfg.poses and q.runs < cfg.runs
    assert [s.track for s in cfg.solvers if s.name == "lm"] == ["jacobian"]
    # what meta.json stores reloads as the same config (fkopt check reruns from it)
    again = from_dict(q.model_dump(mode="json"), "meta")
    assert again.model_dump() == q.model_dump()


@pytest.mark.parametrize("change, fragment", [
    ({"solvers": [{"name": "some.module:Solver"}]}, "needs 'track' (allowed: black-box, jacobian, exact)"),
    ({"solvers": [{"name": "gabc", "track": "grey-box"}]}, "track"),
    ({"sets": ["uniform", "weird"]}, "sets"),
    ({"targets": [1e-4, 1e-2]}, "decreasing order"),
    ({"quick": {"solvers": ["nope"]}}, "quick.solvers: 'nope' is not one of"),
    ({"budget_per_dim": 0}, "budget_per_dim"),
])
def test_bad_suite_fields_are_one_line_errors(tmp_path, change, fragment):
    path = tiny(tmp_path, **change)
    with pytest.raises(FkoptError) as err:
        load_any(path)
    assert fragment in str(err.value) and str(path) in str(err.value) and "\n" not in str(err.value)


# -- pose sets ----------------------------------------------------------------------------------
def test_frozen_pose_sets_are_regenerated_bit_for_bit_from_their_seed():
    cfg = load_suite(SUITE)
    manifest = json.loads((SUITES / "kinbench-v1" / "manifest.json").read_text())
    from fkopt.kinbench.posesets import POSES, csv_bytes
    for problem in cfg.problems[:2]:
        sets, _ = generate(problem, manifest["seed"], POSES, cfg._folder)
        mech, _ = problem_mechanism(problem)
        for name, pts in sets.items():
            digest = hashlib.sha256(csv_bytes(mech.unknown_names, pts)).hexdigest()
            assert digest == manifest["problems"][problem.name]["sets"][name]["sha256"], (problem.name, name)


def test_pose_sets_measure_what_they_claim():
    cfg = load_suite(SUITE)
    sets, manifest = load_pose_sets(cfg)
    for problem in cfg.problems:
        mech, _ = problem_mechanism(problem)
        lo, hi = mech.bounds[:, 0], mech.bounds[:, 1]
        info = manifest["problems"][problem.name]["sets"]
        kappa = condition_numbers(problem, None, sets[(problem.name, "near-singular")])
        assert np.all(kappa > info["near-singular"]["bound"] * (1 - 1e-5)), problem.name
        uni = condition_numbers(problem, None, sets[(problem.name, "uniform")])
        assert np.median(kappa) > np.median(uni), problem.name
        b = sets[(problem.name, "boundary")]
        gap = np.minimum(b - lo, hi - b) / (hi - lo)
        assert np.all(gap.min(axis=1) <= BOUNDARY_SHARE + 1e-12) and np.all(gap >= -1e-12), problem.name
        assert len(sets[(problem.name, "printed")]) >= 1


def test_a_changed_pose_file_is_refused_by_its_checksum(tmp_path, fkopt_run):
    path = tiny(tmp_path)
    f = tmp_path / "kinbench-v1" / "mao2017-3rps" / "uniform.csv"
    f.write_text(f.read_text().replace("1", "2", 1))
    out = tmp_path / "out"
    r = fkopt_run("suite", path, "--out", out, "-q")
    assert r.returncode == 2, r.stderr
    assert r.stderr.count("\n") == 1 and "uniform.csv: SHA-256" in r.stderr and "Traceback" not in r.stderr
    assert not (out / "kinbench").exists()


def test_a_solver_that_cannot_take_a_problem_is_refused_before_solving(tmp_path, fkopt_run):
    data = yaml.safe_load(SUITE.read_text())
    arm = [p for p in data["problems"] if p["name"] == "wang2020-7dof"]
    path = tiny(tmp_path, problems=arm, solvers=[{"name": "pso"}, {"name": "nr"}])
    r = fkopt_run("suite", path, "--out", tmp_path / "out", "-q")
    assert r.returncode == 2 and r.stderr.startswith(f"fkopt: error: {path}: solvers[nr] on problems[wang2020-7dof]: nr needs")
    assert not (tmp_path / "out").exists() or not any(p.is_file() for p in (tmp_path / "out").rglob("*"))


def test_an_exact_solver_of_the_wrong_kind_is_refused_in_one_line(tmp_path, fkopt_run):
    data = yaml.safe_load(SUITE.read_text())
    arm = [p for p in data["problems"] if p["name"] == "wang2020-7dof"]
    path = tiny(tmp_path, problems=arm, solvers=[{"name": "forward"}])
    r = fkopt_run("suite", path, "--out", tmp_path / "out", "-q")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "Traceback" not in r.stderr
    assert "solvers[forward] on problems[wang2020-7dof]: algorithm 'forward' solves forward kinematics" in r.stderr
    assert "use 'exact'" in r.stderr
    assert not (tmp_path / "out").exists() or not any(p.is_file() for p in (tmp_path / "out").rglob("*"))


def test_a_mechanism_other_than_the_pose_sets_one_is_refused(tmp_path):
    data = yaml.safe_load(SUITE.read_text())
    probs = data["problems"][:1]
    probs[0]["mechanism"]["geometry"]["ra"] = 275
    with pytest.raises(FkoptError, match=r"problems\[mao2017-3rps\].mechanism: differs"):
        from fkopt.run.pipeline import validate_any
        validate_any(load_any(tiny(tmp_path, problems=probs)))


# -- measures -----------------------------------------------------------------------------------
def test_at_budget_cuts_every_measure_at_the_budget():
    hist = np.array([[1.0, 1e-3, 1e-5, 1e-11], [1.0, 0.5, 0.5, 0.5]])
    ev = np.array([[10, 20, 30, 40], [10, 20, 30, 40]])
    m = at_budget(hist, ev, 35, [1e-2, 1e-4, 1e-10])
    assert m["evaluations"].tolist() == [30, 30] and m["fitness"].tolist() == [1e-5, 0.5]
    assert m[target_column(1e-2)].tolist()[0] == 20 and np.isnan(m[target_column(1e-2)][1])
    assert np.isnan(m[target_column(1e-10)][0])        # reached at 40 > budget 35


def _runs(rows):
    cols = ["problem", "class", "set", "pose", "solver", "track", "run", "dim", "budget", "evaluations", "fitness",
            target_column(1e-2), target_column(1e-6)]
    return pd.DataFrame(rows, columns=cols)


def test_ert_and_success_rate_follow_coco():
    nan = np.nan
    runs = _runs([["p", "c", "u", 0, "a", "black-box", 0, 2, 100, 40, 1e-7, 10, 40],
                  ["p", "c", "u", 0, "a", "black-box", 1, 2, 100, 100, 1e-3, 30, nan],
                  ["p", "c", "u", 0, "a", "black-box", 2, 2, 100, 100, 1.0, nan, nan]])
    t = M.measures_table(runs, [1e-2, 1e-6]).set_index("target")
    assert t.loc[1e-2, "success_rate"] == pytest.approx(2 / 3)
    assert t.loc[1e-2, "ert"] == pytest.approx((10 + 30 + 100) / 2)
    assert t.loc[1e-6, "ert"] == pytest.approx((40 + 100 + 100) / 1) and t.loc[1e-6, "ert_per_dim"] == 120
    e = M.ecdf_table(runs, [1e-2, 1e-6], 50)
    e = e[e.scope == "all"]
    assert e["fraction"].is_monotonic_increasing and e["fraction"].iloc[-1] == pytest.approx(3 / 6)
    # targets reached after 10, 30 (1e-2) and 40 (1e-6) evaluations, dimension 2, of 6 (triple, run) pairs
    assert e[["evals_per_dim", "reached", "pairs"]].values.tolist() == [[5, 1, 6], [15, 2, 6], [20, 3, 6]]


def test_the_scaling_table_gives_ert_per_dimension_for_classes_of_several_dimensions():
    nan = np.nan
    same = _runs([["p", "c", "u", 0, "a", "black-box", 0, 2, 100, 40, 1e-7, 10, 40],
                  ["q", "c", "u", 0, "a", "black-box", 0, 2, 100, 40, 1e-7, 10, 40]])
    assert M.scaling_table(same, [1e-2, 1e-6]) is None          # one dimension per class: no file
    runs = _runs([["chain-3", "chain", "u", 0, "a", "black-box", 0, 3, 300, 60, 1e-7, 30, 60],
                  ["chain-3", "chain", "u", 1, "a", "black-box", 0, 3, 300, 300, 1e-3, 90, nan],
                  ["chain-6", "chain", "u", 0, "a", "black-box", 0, 6, 600, 600, 1.0, nan, nan],
                  ["chain-6", "chain", "b", 0, "a", "black-box", 0, 6, 600, 240, 1e-7, 120, 240]])
    t = M.scaling_table(runs, [1e-2, 1e-6]).set_index(["dim", "target"])
    assert t.loc[(3, 1e-2), "ert"] == pytest.approx((30 + 90) / 2) and t.loc[(3, 1e-2), "trials"] == 2
    assert t.loc[(3, 1e-6), "ert_per_dim"] == pytest.approx((60 + 300) / 1 / 3)
    assert t.loc[(6, 1e-6), "ert"] == pytest.approx((600 + 240) / 1)     # sets pooled within a dimension
    assert list(t.reset_index()["class"].unique()) == ["chain"]


def test_ranking_finds_a_real_difference_and_no_fake_one():
    rng = np.random.default_rng(0)
    base = rng.random(40)
    scores = pd.DataFrame({"good": base + 0.2, "bad": base, "twin": base + rng.normal(0, 1e-3, 40)})
    r = M.rank_scope(scores, 1000, 0.05, 1, "s").set_index("solver")
    assert r.loc["good", "rank"] == 1 and set(r.loc["good", "better_than"].split(";")) == {"bad", "twin"}
    assert r.loc["twin", "better_than"] == "" and r.loc["bad", "better_than"] == ""
    assert r.loc["good", "ci_low"] < r.loc["good", "score"] < r.loc["good", "ci_high"]


# -- end to end ---------------------------------------------------------------------------------
def test_fkopt_suite_writes_the_leaderboard_and_fkopt_check_reruns_it(tmp_path):
    path = tiny(tmp_path)
    out = tmp_path / "out"
    r = cli("suite", path, "--out", out, "-q")
    assert r.returncode == 0, r.stderr
    folder = out / "kinbench" / "tiny"
    for name in ("leaderboard.csv", "leaderboard.md", "measures.csv", "ecdf.csv", "runs.csv", "timing.csv",
                 "index.html", "ecdf_all.png", "ecdf_all.pdf", "ecdf_parallel-fk-3dof.png", "meta.json"):
        assert (folder / name).is_file(), name
    lb = pd.read_csv(folder / "leaderboard.csv")
    assert set(lb.loc[lb.scope == "overall", "solver"]) == {"pso", "lm"}
    assert {"overall", "track:black-box", "track:jacobian"} <= set(lb.scope)
    runs = pd.read_csv(folder / "runs.csv")
    assert len(runs) == 2 * 2 * (4 * 2) * 2     # problems x solvers x (4 sets x 2 poses) x runs
    assert (runs["evaluations"] <= runs["budget"]).all()
    page = (folder / "index.html").read_text()
    assert "http://" not in page and "https://" not in page and "<script src" not in page and "<link" not in page
    images = re.findall(r'<img [^>]*src="([^"]+)"', page)          # the figures beside the page, by name
    assert "ecdf_all.png" in images and all((folder / src).is_file() for src in images)
    assert "Which solver for which problem class" in page and ">Ranking overall<" in (folder / "rankings.html").read_text()
    assert "## Per track" in (folder / "leaderboard.md").read_text()
    chk = cli("check", folder)
    assert chk.returncode == 0, chk.stdout + chk.stderr
    from fkopt.run.pipeline import prepare_output
    assert prepare_output(load_any(path), out) == folder     # the same suite may rewrite it without --force
    with pytest.raises(FkoptError, match="different config"):
        prepare_output(load_any(tiny(tmp_path / "other", runs=3)), out)
    lb.loc[0, "score"] += 0.01                 # a stored number that the rerun does not give
    lb.to_csv(folder / "leaderboard.csv", index=False, float_format="%.10g")
    chk = cli("check", folder)
    assert chk.returncode == 1 and "leaderboard.csv" in chk.stderr, chk.stdout + chk.stderr


def test_fkopt_run_accepts_a_suite_and_numbers_do_not_depend_on_other_solvers(tmp_path):
    path = tiny(tmp_path)
    one = load_any(tiny(tmp_path / "b", solvers=[{"name": "lm"}]))
    both = load_any(path)
    a = run_config(both, tmp_path / "o1", source=str(path)).result.record
    b = run_config(one, tmp_path / "o2", source=str(tmp_path / "b" / "tiny.yaml")).result.record
    pd.testing.assert_frame_equal(a[a.solver == "lm"].reset_index(drop=True), b.reset_index(drop=True))


def test_a_plugin_algorithm_from_examples_gets_a_leaderboard_row(tmp_path, monkeypatch):
    """examples/plugin's DE, named by direct reference: nothing in fkopt knows it."""
    monkeypatch.syspath_prepend(str(ROOT / "examples" / "plugin"))
    path = tiny(tmp_path, solvers=[{"name": "fkopt_example.de:DE", "label": "de", "track": "black-box"},
                                   {"name": "pso"}])
    res = run_config(load_any(path), tmp_path / "out", source=str(path))
    lb = pd.read_csv(res.folder / "leaderboard.csv")
    row = lb[(lb.scope == "track:black-box") & (lb.solver == "de")]
    assert len(row) == 1 and row["track"].item() == "black-box" and 0 <= row["score"].item() <= 1


def test_reproduce_does_not_pick_up_suites(tmp_path):
    from fkopt.reproduce.run import plan
    shutil.copytree(SUITES, tmp_path / "configs" / "suites")
    shutil.copy(ROOT / "configs" / "wu2015" / "tab2_nr.yaml", tmp_path / "configs" / "one.yaml")
    planned = plan(tmp_path / "configs", tmp_path / "out")
    assert [p.path.name for p in planned] == ["one.yaml"]


def _outside_csv(path, rows_of):
    """An outside solver's log: for every instance and 2 runs, rows_of(problem, set, pose, run) rows."""
    cfg = load_suite(path)
    sets, _ = load_pose_sets(cfg)
    rows = []
    for (problem, name), pts in sets.items():
        for i in range(len(pts)):
            for run in range(2):
                rows += [dict(problem=problem, set=name, pose=i, run=run, evaluations=e, best_so_far=f)
                         for e, f in rows_of(problem, name, i, run)]
    return pd.DataFrame(rows)


def test_outside_results_are_ranked_beside_fkopts(tmp_path):
    path = tiny(tmp_path)
    # a perfect outside solver: every target at 2 x dim evaluations; and one that never gets close
    _outside_csv(path, lambda *a: [(1, 5.0), (6, 1e-12), (1000, 1e-13)]).to_csv(tmp_path / "fast.csv", index=False)
    _outside_csv(path, lambda *a: [(1, 5.0), (300, 1.0)]).to_csv(tmp_path / "slow.csv", index=False)
    path = tiny(tmp_path / "s", outside=[{"solver": "ext-fast", "track": "black-box", "file": "../fast.csv"},
                                         {"solver": "ext-slow", "track": "black-box", "file": "../slow.csv"}])
    res = run_config(load_any(path), tmp_path / "out", source=str(path))
    lb = pd.read_csv(res.folder / "leaderboard.csv")
    bb = lb[lb.scope == "track:black-box"].set_index("solver")
    assert bb.loc["ext-fast", "rank"] == 1 and bb.loc["ext-slow", "score"] == 0
    assert set(bb.index) == {"ext-fast", "ext-slow", "pso"}
    assert bb.loc["ext-fast", "success_1e-10"] == 1
    expected = np.log(100 / 2) / np.log(100)    # all 5 targets at 6 evaluations / dim 3 = 2 per dim
    assert bb.loc["ext-fast", "score"] == pytest.approx(expected)
    meta = json.loads((res.folder / "meta.json").read_text())
    assert set(meta["outside"]) == {"ext-fast", "ext-slow"}


def test_an_outside_file_missing_an_instance_is_refused_before_solving(tmp_path, fkopt_run):
    path = tiny(tmp_path)
    df = _outside_csv(path, lambda *a: [(1, 5.0)])
    df[~((df.problem == "wu2015-3ppr") & (df.set == "boundary") & (df.pose == 1))].to_csv(tmp_path / "x.csv",
                                                                                          index=False)
    path = tiny(tmp_path / "s", outside=[{"solver": "ext", "track": "exact", "file": "../x.csv"}])
    out = tmp_path / "out"
    r = fkopt_run("suite", path, "--out", out, "-q")
    assert r.returncode == 2 and "no run of problem wu2015-3ppr, set boundary, pose 1" in r.stderr
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr
    assert not out.exists() or not any(p.is_file() for p in out.rglob("*"))


def test_worker_processes_and_a_dask_scheduler_write_the_same_bytes(tmp_path):
    path = tiny(tmp_path, solvers=[{"name": "lm"}, {"name": "pso"}])
    a = run_config(load_any(path), tmp_path / "one", source=str(path)).folder
    b = run_config(load_any(path), tmp_path / "two", source=str(path), jobs=2).folder
    folders = [b]
    try:
        from dask.distributed import LocalCluster
    except ImportError:
        LocalCluster = None
    if LocalCluster is not None:     # an existing cluster reached by its address, as with --scheduler
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
            folders.append(run_config(load_any(path), tmp_path / "dask", source=str(path), executor="dask",
                                      scheduler=cluster.scheduler_address).folder)
    for other in folders:
        for name in ("runs.csv", "trace.csv.gz", "measures.csv", "ecdf.csv", "leaderboard.csv"):
            assert (a / name).read_bytes() == (other / name).read_bytes(), (other, name)
    if LocalCluster is None:
        pytest.skip("dask.distributed not installed: only the worker processes were compared")


def test_runs_logged_by_iohexperimenter_are_ranked(tmp_path):
    """Outside runs written by IOHexperimenter's own Analyzer logger (not by fkopt) are read back
    with the best-so-far fitness the runs really reached."""
    ioh = pytest.importorskip("ioh", reason="IOHexperimenter (pip install ioh) is not installed")
    from fkopt.kinds.experiment.runner import make_problem
    from fkopt.kinbench.posesets import targets_of
    path = tiny(tmp_path)
    cfg = load_suite(path)
    sets, _ = load_pose_sets(cfg)
    logger = ioh.logger.Analyzer(root=str(tmp_path / "ioh-runs"), folder_name="rs", algorithm_name="RS")
    best = {}
    for problem in cfg.problems:
        mech, rc = problem_mechanism(problem)
        lo, hi = mech.bounds[:, 0], mech.bounds[:, 1]
        for name in cfg.sets:
            for i, point in enumerate(sets[(problem.name, name)]):
                prob = make_problem(rc, mech, targets_of(mech, point[None])[0])
                f = ioh.wrap_problem(lambda x, p=prob: float(p.fitness(np.asarray(x))), name=f"{problem.name}__{name}",
                                     optimization_type=ioh.OptimizationType.MIN, dimension=len(lo), instance=i + 1,
                                     lb=-1000.0, ub=1000.0)
                f.attach_logger(logger)
                rng = np.random.default_rng(i)
                for run in range(2):
                    xs = lo + rng.random((40, len(lo))) * (hi - lo)
                    best[(problem.name, name, i, run)] = min(f(list(x)) for x in xs)
                    f.reset()
    logger.close()
    path = tiny(tmp_path / "s", outside=[{"solver": "ioh-rs", "track": "black-box", "ioh": "../ioh-runs"}])
    res = run_config(load_any(path), tmp_path / "out", source=str(path))
    runs = res.result.record
    got = runs[runs.solver == "ioh-rs"]
    assert len(got) == len(best)
    for r in got.itertuples():
        assert r.evaluations == 40 and r.fitness == pytest.approx(best[(r.problem, r.set, r.pose, r.run)], rel=1e-9)
    lb = pd.read_csv(res.folder / "leaderboard.csv")
    assert "ioh-rs" in set(lb.loc[lb.scope == "track:black-box", "solver"])


def test_a_urdf_arm_joins_as_a_problem_with_pose_sets_of_its_own(tmp_path):
    """The hook for URDF arms: a problem is a mechanism spec; its frozen sets are generated like v1's."""
    from fkopt.kinbench.posesets import write_pose_sets
    urdf = ROOT / "fkopt" / "mechanisms" / "data" / "wang7dof.urdf"
    data = {"kind": "suite", "name": "urdf", "pose_sets": "kb-urdf", "sets": ["uniform", "near-singular", "boundary"],
            "problems": [{"name": "urdf-7dof", "problem_class": "serial-ik-7dof", "objective": "geodesic",
                          "mechanism": {"name": "urdf", "bounds": {"q1": [-180, 180]},
                                        "geometry": {"file": str(urdf), "base": "link0", "tip": "tool"}}}],
            "solvers": [{"name": "lm"}], "poses": 1, "runs": 1, "budget_per_dim": 200, "bootstrap": 100}
    path = tmp_path / "urdf.yaml"
    path.write_text(yaml.safe_dump(data))
    cfg = load_suite(path)
    write_pose_sets(cfg, tmp_path / "kb-urdf")
    res = run_config(load_any(path), tmp_path / "out", source=str(path))
    runs = res.result.record
    assert len(runs) == 3 and set(runs["set"]) == {"uniform", "near-singular", "boundary"}
    assert (runs["dim"] == 7).all() and (runs["evaluations"] <= 200 * 7).all()


def test_an_interrupted_suite_resumes_with_the_same_bytes(tmp_path):
    from fkopt.kinbench.kind import work_folder
    path = tiny(tmp_path)
    whole = run_config(load_any(path), tmp_path / "whole", source=str(path)).folder

    class Stop(KeyboardInterrupt):
        pass

    def stop_after_two(label, done, total):
        if done == 2:
            raise Stop
    out = tmp_path / "out"
    with pytest.raises(Stop):
        run_config(load_any(path), out, source=str(path), progress=stop_after_two)
    work = work_folder(out, load_any(path))
    kept = sorted((work / "tasks").glob("p*-s*.json"))
    assert len(kept) == 2 and not (out / "kinbench" / "tiny").exists()
    assert all(set(json.loads(p.read_text())["trace"]) == {"row", "evaluations", "best_fitness"} for p in kept)
    seen = []
    folder = run_config(load_any(path), out, source=str(path), resume=True,
                        progress=lambda label, done, total: seen.append((done, total))).folder
    assert seen == [(2, 4), (3, 4), (4, 4)]         # two resumed, only the two missing tasks solved
    for name in ("runs.csv", "measures.csv", "ecdf.csv", "leaderboard.csv", "trace.csv.gz"):
        assert (folder / name).read_bytes() == (whole / name).read_bytes(), name
    assert not work.exists()
    # a task file of an earlier fkopt (no trace) is refused in one line, not a traceback
    with pytest.raises(Stop):
        run_config(load_any(path), out, source=str(path), progress=stop_after_two)
    rec = json.loads(kept[0].read_text())
    del rec["trace"]
    kept[0].write_text(json.dumps(rec))
    with pytest.raises(FkoptError, match="changed since fkopt wrote it"):      # its digest no longer fits
        run_config(load_any(path), out, source=str(path), resume=True)
    manifest = json.loads((work / "tasks" / "manifest.json").read_text())     # even with a forged digest
    manifest["tasks"][kept[0].stem] = hashlib.sha256(kept[0].read_bytes()).hexdigest()
    (work / "tasks" / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(FkoptError, match="not a finished task of this run .field 'trace' is missing"):
        run_config(load_any(path), out, source=str(path), resume=True)
    # tasks of another version of the suite are never mixed in
    with pytest.raises(FkoptError, match="another version of suite"):
        run_config(load_any(tiny(tmp_path / "v2", runs=3)), out, source=str(path), resume=True, force=True)


# -- kinbench v2: URDF arms, Dietmaier's platform, the exact track -------------------------------
SUITE_V2 = SUITES / "kinbench-v2.yaml"
V2_NEW = ("dietmaier-6sps", "ur5", "panda", "kinova-j2s6s200")


def test_v2_pose_sets_regenerate_byte_identically_and_keep_v1s_sets(tmp_path):
    from fkopt.kinbench.posesets import write_pose_sets
    cfg = load_suite(SUITE_V2)
    sets, manifest = load_pose_sets(cfg)                 # every checksum of the committed folder verified
    assert set(V2_NEW) <= set(manifest["problems"]) and manifest["version"] == "kinbench-v2"
    fresh = write_pose_sets(cfg, tmp_path / "kinbench-v2")
    committed = SUITES / "kinbench-v2"
    files = sorted(p.relative_to(committed) for p in committed.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(fresh) for p in fresh.rglob("*") if p.is_file())
    for rel in files:
        assert (fresh / rel).read_bytes() == (committed / rel).read_bytes(), rel
    v1 = json.loads((SUITES / "kinbench-v1" / "manifest.json").read_text())
    for name, entry in v1["problems"].items():          # v1's problems keep v1's sets, byte for byte
        assert manifest["problems"][name] == entry, name
        for meta in entry["sets"].values():
            assert (committed / meta["file"]).read_bytes() == (SUITES / "kinbench-v1" / meta["file"]).read_bytes()
    for name in V2_NEW:
        assert len(sets[(name, "uniform")]) == cfg.poses
    lib = load_suite(SUITES / "kinbench-v2-libraries.yaml")      # the pymoo/NiaPy subset reads the same sets
    lib_sets, _ = load_pose_sets(lib)
    for key, pts in lib_sets.items():
        assert np.array_equal(pts, sets[key][: lib.poses])


def test_v2_urdf_copies_match_example_robot_data():
    """The suite's kinematics-only URDF copies give example-robot-data's FK (when it is installed)."""
    urdf = pytest.importorskip("fkopt.mechanisms.urdf")
    if urdf.example_robots_folder() is None:
        pytest.skip("example-robot-data is not installed")
    cfg = load_suite(SUITE_V2)
    for problem, robot in (("ur5", "ur5"), ("panda", "panda"), ("kinova-j2s6s200", "kinova")):
        mech, _ = problem_mechanism(next(p for p in cfg.problems if p.name == problem), SUITES)
        ref = urdf.example_robot(robot)
        assert mech.joint_names == ref.joint_names and np.array_equal(mech.bounds, ref.bounds)
        q = mech.bounds[:, 0] + np.random.default_rng(7).random((20, mech.dof)) * np.diff(mech.bounds).ravel()
        assert np.array_equal(mech.fk(q), ref.fk(q)), problem


def test_exact_solvers_give_fkopt_forward_and_inverse_numbers_and_count_their_evaluations():
    import fkopt
    from fkopt.problems import fk_problem, ik_problem
    from fkopt.solve import solve
    from fkopt.kinematics.as_algorithms import row_seeds
    from fkopt.numerics.streams import RunStreams
    m = fkopt.mechanism("3-rps", ra=274, rb=158)
    poses = m.bounds[:, 0] + np.random.default_rng(3).random((3, 3)) * np.diff(m.bounds).ravel()
    res = solve(fk_problem(m, m.ik(poses)), "exact", population=20, iterations=4, runs=2, seed=[5, 6, 7])
    seeds = row_seeds(RunStreams(np.repeat([5, 6, 7], 2), np.tile([0, 1], 3)))
    for c in range(3):
        ref = fkopt.forward(m, m.ik(poses[c]), seed=seeds[2 * c])
        assert np.array_equal(res.x[c, 0], ref.pose)
        used = int(ref.evaluations["residual"] + ref.evaluations["jacobian"]) + 1     # + the fitness of the answer
        assert (res.evaluation_history[c, 0] == used).all() and res.fitness[c, 0] < 1e-10
    arm = fkopt.mechanism("7dof-arm")
    q = arm.bounds[:, 0] + np.random.default_rng(4).random((2, 7)) * np.diff(arm.bounds).ravel()
    ik = ik_problem(arm, arm.fk(q))
    res = solve(ik, "inverse", population=20, iterations=2, runs=1, seed=[1, 2])
    seeds = row_seeds(RunStreams([1, 2], [0, 0]))
    for c in range(2):
        ref = fkopt.inverse(arm, ik.target[c], seed=seeds[c])     # the problem's target pose, as stored
        assert np.array_equal(res.x[c, 0], ref.joints)
        assert res.evaluation_history[c, 0, -1] == int(ref.evaluations["residual"] + ref.evaluations["jacobian"]) + 1
    with pytest.raises(FkoptError, match="forward kinematics of a parallel mechanism"):
        solve(ik_problem(arm, arm.fk(q)), "forward", population=20, iterations=2, runs=1, seed=[1, 2])


def test_an_exact_answer_past_the_budget_does_not_count():
    hist = np.array([[1e-20, 1e-20]])
    m = at_budget(hist, np.array([[300, 300]]), 200, [1e-2])
    assert m["fitness"][0] == np.inf and np.isnan(m[target_column(1e-2)][0])
    assert m["evaluations"][0] == 200          # it spent the budget without an answer: counts B toward ERT


@pytest.fixture(scope="module")
def v2_quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("v2") / "out"
    r = cli("suite", SUITE_V2, "--out", out, "--quick", "-q")
    assert r.returncode == 0, r.stderr
    return out / "kinbench" / "kinbench-v2-quick"


def test_v2_quick_tier_ranks_urdf_arms_dietmaier_and_the_exact_track(v2_quick):
    lb = pd.read_csv(v2_quick / "leaderboard.csv")
    runs = pd.read_csv(v2_quick / "runs.csv")
    assert set(V2_NEW) <= set(runs["problem"])
    assert {"class:serial-ik-6dof/track:exact", "class:serial-ik-7dof/track:black-box",
            "class:parallel-fk-6dof/track:jacobian"} <= set(lb.scope)
    md = (v2_quick / "leaderboard.md").read_text()
    for name in V2_NEW:
        assert name in md, name
    exact = lb[lb.scope == "track:exact"]
    assert list(exact.solver) == ["exact"] and int(exact["rank"].iloc[0]) == 1
    for track in ("track:black-box", "track:jacobian"):
        assert "exact" not in set(lb.loc[lb.scope == track, "solver"])
    ex = runs[runs.solver == "exact"]
    # evaluations counted (>= the solver's one + the fitness) and cut at the budget: 0 = no answer within B
    assert (ex.track == "exact").all() and (ex.evaluations <= ex.budget).all()
    assert ((ex.evaluations >= 2) | ((ex.evaluations == 0) & (ex.fitness == np.inf))).all()
    # fkopt.inverse solves the URDF arms' IK to the first target on most poses within the budget
    # (fkopt.forward on Dietmaier's platform mostly needs its global stage, past 500 x 6 evaluations)
    for name in ("ur5", "panda", "kinova-j2s6s200"):
        assert ex.loc[ex.problem == name, target_column(1e-2)].notna().mean() > 0.5, name


def test_fkopt_check_passes_on_the_v2_quick_tier_and_fails_on_an_edited_number(v2_quick, tmp_path):
    folder = tmp_path / "kinbench-v2-quick"
    shutil.copytree(v2_quick, folder)
    chk = cli("check", folder)
    assert chk.returncode == 0, chk.stdout + chk.stderr
    lb = pd.read_csv(folder / "leaderboard.csv")
    row = lb.index[(lb.scope == "track:exact")][0]
    lb.loc[row, "score"] += 0.01
    lb.to_csv(folder / "leaderboard.csv", index=False, float_format="%.10g")
    chk = cli("check", folder)
    assert chk.returncode == 1 and "leaderboard.csv" in chk.stderr, chk.stdout + chk.stderr


# -- kinbench v3: real arms, geometry instances, the chain family, 100 poses, a unit-free measure --
SUITE_V3 = SUITES / "kinbench-v3.yaml"


def test_v3_holds_the_breadth_and_its_frozen_sets_verify():
    from fkopt.kinbench.instances import SPREADS
    from fkopt.kinbench.robots import ARMS
    cfg = load_suite(SUITE_V3)
    sets, manifest = load_pose_sets(cfg)               # every checksum of the committed folder verified
    assert manifest["version"] == "kinbench-v3" and manifest["near_singular_measure"] == "sigma"
    names = {p.name: p for p in cfg.problems}
    for arm in ARMS:                                   # the 22 arms, each from its stored copy
        assert names[arm.name].mechanism.geometry == {"file": arm.file, "base": arm.base, "tip": arm.tip}
    chains = sorted(p.mechanism.geometry["joints"] for p in cfg.problems if p.mechanism.name == "dh-chain")
    assert chains[0] == 3 and chains[-1] == 30 and len(chains) >= 10
    for mech in SPREADS:                               # >= 10 instances of every parallel mechanism
        inst = [p for p in cfg.problems if p.mechanism.name == mech and "-i" in p.name]
        assert len(inst) >= 10 and len({repr(p.mechanism.geometry) for p in inst}) == len(inst), mech
    for (problem, name), pts in sets.items():
        if name != "printed":
            assert len(pts) >= 100, (problem, name)
    quick = cfg.quick_tier()
    assert {p.name for p in quick.problems} <= set(names) and quick.poses == 2


def test_v3_pose_sets_regenerate_bit_for_bit_from_their_seed():
    """A sample of v3's problems (an instance, a URDF arm with a mimic, an MJCF arm, chains) regenerated
    from the manifest's seed, size and measure give the committed bytes."""
    from fkopt.kinbench.posesets import csv_bytes
    cfg = load_suite(SUITE_V3)
    manifest = json.loads((SUITES / "kinbench-v3" / "manifest.json").read_text())
    for name in ("chang2024-3rpupc-i4", "pr2-left-gripper", "gr1-left-mj", "dh-chain-25"):
        problem = next(p for p in cfg.problems if p.name == name)
        mech, _ = problem_mechanism(problem, SUITES)
        fresh, info = generate(problem, manifest["seed"], manifest["poses_per_set"], SUITES, "sigma")
        for set_name, pts in fresh.items():
            committed = (SUITES / "kinbench-v3" / name / f"{set_name}.csv").read_bytes()
            assert csv_bytes(mech.unknown_names, pts) == committed, (name, set_name)
        assert info["near-singular"] == {k: v for k, v in manifest["problems"][name]["sets"]["near-singular"].items()
                                         if k not in ("file", "sha256", "poses")}


def test_v3_near_singular_sets_are_nearer_to_a_singularity_than_uniform_ones():
    from fkopt.kinbench.measures import unit_free_sigma_min
    cfg = load_suite(SUITE_V3)
    sets, manifest = load_pose_sets(cfg)
    for name in ("mao2017-3rps-i2", "dietmaier-6sps", "ur5", "iiwa-mj", "dh-chain-7"):
        problem = next(p for p in cfg.problems if p.name == name)
        mech, _ = problem_mechanism(problem, SUITES)
        meta = manifest["problems"][name]["sets"]["near-singular"]
        near = unit_free_sigma_min(mech, sets[(name, "near-singular")], meta["characteristic_length"])
        uniform = unit_free_sigma_min(mech, sets[(name, "uniform")], meta["characteristic_length"])
        assert np.all(near < meta["bound"] * (1 + 1e-5)) and np.mean(uniform > meta["bound"]) > 0.8, name


def test_the_unit_free_singularity_measure_does_not_depend_on_units_or_scale():
    import fkopt
    from fkopt.kinbench.measures import characteristic_length, unit_free_sigma_min
    mm, m = fkopt.mechanism("7dof-arm"), fkopt.mechanism("urdf")     # wang7dof's arm in mm (DH) and in m (URDF)
    q = mm.bounds[:, 0] + np.random.default_rng(0).random((50, 7)) * np.diff(mm.bounds).ravel()
    L_mm, L_m = characteristic_length(mm, q), characteristic_length(m, q)
    assert L_mm == pytest.approx(1000 * L_m)
    assert np.allclose(unit_free_sigma_min(mm, q, L_mm), unit_free_sigma_min(m, q, L_m), rtol=1e-9, atol=1e-12)
    small = fkopt.mechanism("3-rps", ra=274, rb=158)                  # the same 3-RPS, twice as large
    large = fkopt.mechanism("3-rps", ra=548, rb=316, bounds={"z": (800, 1400)})
    x = small.bounds[:, 0] + np.random.default_rng(1).random((50, 3)) * np.diff(small.bounds).ravel()
    s_small = unit_free_sigma_min(small, x, characteristic_length(small, x))
    s_large = unit_free_sigma_min(large, x * [1, 1, 2], characteristic_length(large, x))
    assert np.allclose(s_small, s_large, rtol=1e-6) and np.all(s_small > 0)
    ur5 = fkopt.mechanism("urdf", file=str(SUITES / "robots" / "ur5.urdf"), base="base_link", tip="tool0")
    stretched = np.array([[0.0, -90.0, 0.0, -90.0, 0.0, 0.0]])           # elbow straight: UR5's singularity
    assert unit_free_sigma_min(ur5, stretched, 1.0)[0] < 1e-12 < unit_free_sigma_min(ur5, stretched + 30, 1.0)[0]


def test_v3_quick_tier_ranks_instances_urdf_and_mjcf_arms_and_chains(tmp_path):
    r = cli("suite", SUITE_V3, "--out", tmp_path / "out", "--quick", "-q")
    assert r.returncode == 0, r.stderr
    folder = tmp_path / "out" / "kinbench" / "kinbench-v3-quick"
    runs = pd.read_csv(folder / "runs.csv")
    quick = load_suite(SUITE_V3).quick_tier()
    assert set(runs["problem"]) == {p.name for p in quick.problems}
    assert set(runs.loc[runs.problem.str.startswith("dh-chain"), "dim"]) == {3, 12, 30}
    lb = pd.read_csv(folder / "leaderboard.csv")
    assert {"class:dh-chain/track:exact", "class:serial-ik-8to10dof/track:jacobian",
            "class:parallel-fk-6dof/track:black-box"} <= set(lb.scope)
    scaling = pd.read_csv(folder / "scaling.csv")            # cost against the number of joints
    assert set(scaling.loc[scaling["class"] == "dh-chain", "dim"]) == {3, 12, 30}
    assert (folder / "scaling_dh-chain.png").exists() and "## Cost against dimension" in \
        (folder / "leaderboard.md").read_text()
    ex = runs[runs.solver == "exact"]
    for name in ("ur5", "iiwa-mj", "pr2-left-gripper", "g1-left", "gr1-left-mj", "dh-chain-12"):
        assert ex.loc[ex.problem == name, target_column(1e-2)].notna().mean() > 0.5, name
