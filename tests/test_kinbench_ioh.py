"""A suite's trace.csv.gz and its IOHprofiler export, read back with iohinspector (the IOHprofiler
project's reader, not fkopt's): every run is there, ending at runs.csv's fitness within the budget."""
import json
import warnings

import numpy as np
import pandas as pd
import pytest

from fkopt.run.pipeline import load_any, run_config
from fkopt.kinbench.budget import at_budget
from fkopt.kinbench.traces import COLUMNS, KEYS, budget_trace
from test_cli import assert_one_line_error
from test_kinbench import _outside_csv, tiny

SOLVERS = [{"name": "pso"}, {"name": "lm"}, {"name": "exact", "track": "exact"}]


@pytest.fixture(scope="module")
def suite(tmp_path_factory):
    """A tiny suite: 2 problems x 4 sets x 2 poses, pso, lm and the exact solver x 2 runs, and an
    outside solver whose log starts after evaluation 1 and runs past the budget (300 = 100 x 3)."""
    tmp = tmp_path_factory.mktemp("suite")
    path = tiny(tmp)
    _outside_csv(path, lambda p, s, i, run: [(0, 50.0 + run), (7, 3.0), (7, 2.5), (120 + i, 1e-5), (400, 1e-12)]
                 ).to_csv(tmp / "ext.csv", index=False)
    path = tiny(tmp / "s", solvers=SOLVERS, outside=[{"solver": "ext", "track": "black-box", "file": "../ext.csv"}])
    res = run_config(load_any(path), tmp / "out", source=str(path))
    return path, res.folder


def test_every_run_has_a_trace_ending_at_its_runs_csv_measures(suite):
    _, folder = suite
    runs = pd.read_csv(folder / "runs.csv")
    trace = pd.read_csv(folder / "trace.csv.gz")
    assert tuple(trace.columns) == COLUMNS
    assert len(runs) == 2 * 4 * 2 * (3 + 1) * 2          # problems x (sets x poses) x solvers x runs
    first = trace.groupby(KEYS, sort=False).head(1)
    last = trace.groupby(KEYS, sort=False).tail(1).reset_index(drop=True)
    assert (last[KEYS].to_numpy() == runs[KEYS].to_numpy()).all()      # one run per runs.csv row, in its order
    assert (first.evaluations == 1).all() and (last.evaluations <= runs.budget).all()
    assert (last.best_fitness.to_numpy() == runs.fitness.to_numpy()).all()
    assert (last.evaluations.to_numpy() == runs.evaluations.to_numpy()).all()   # nothing past the budget cut
    for _, g in trace.groupby(KEYS):
        assert (np.diff(g.evaluations) > 0).all() and (np.diff(g.best_fitness) <= 0).all()
    # exact evaluations: no later than the iteration-end counts runs.csv's targets are read at
    for t in (1e-2, 1e-6, 1e-10):
        hit = trace[trace.best_fitness < t].groupby(KEYS).evaluations.min()
        col = runs.set_index(KEYS)[f"evals_to_{t:.0e}"]
        assert set(hit.index) == set(col.dropna().index) and (hit <= col.loc[hit.index]).all()
    ext = trace[trace.solver == "ext"]       # logged (0, 50), (7, 3), (7, 2.5), (120 + pose, 1e-5), (400, ...)
    run = ext[(ext.problem == "mao2017-3rps") & (ext.set == "uniform") & (ext.pose == 1) & (ext.run == 1)]
    assert run.evaluations.tolist() == [1, 7, 121] and run.best_fitness.tolist() == [51.0, 2.5, 1e-5]
    ex = trace[trace.solver == "exact"].groupby(KEYS).head(1)   # the answer is its first value: inf before it
    assert (ex.best_fitness == np.inf).all()


def test_the_ioh_export_of_a_suite_loads_every_run_in_iohinspector(suite, tmp_path, fkopt_run):
    import iohinspector  # a test dependency (pyproject: test extra)
    path, folder = suite
    out = tmp_path / "ioh"
    proc = fkopt_run("export", folder, "--format", "ioh", "--out", out)
    assert proc.returncode == 0, proc.stderr
    runs = pd.read_csv(folder / "runs.csv")
    with warnings.catch_warnings():     # iohinspector warns (and skips) on a file it cannot read
        warnings.simplefilter("error")
        dm = iohinspector.DataManager()
        dm.add_folder(str(out))
    overview = dm.overview.to_pandas()
    assert len(overview) == len(runs) == 2 * 8 * 4 * 2       # every run: problems x poses x solvers x runs
    assert len(dm.data_sets) == 2 * 4                         # (problem, solver) pairs
    data = dm.load(monotonic=False).to_pandas()
    problems = ["mao2017-3rps", "wu2015-3ppr"]
    checked = 0
    for ds in dm.data_sets:
        fid, fname = ds.function.id, ds.function.name
        assert problems.index(fname) + 1 == fid                       # function_id = problem order
        attrs = dict(ds.experiment_attributes)
        inst = {int(i): lab for i, lab in (x.split("=") for x in attrs["instances"].split("; "))}
        assert list(inst.values())[:3] == ["uniform/0", "uniform/1", "near-singular/0"]
        sc = ds.scenarios[0]
        assert sc.dimension == 3
        for r in sc.runs:
            s, pose = inst[r.instance].split("/")
            mine = runs[(runs.problem == fname) & (runs.solver == ds.algorithm.name) & (runs.set == s)
                        & (runs.pose == int(pose))].sort_values("run")
            k = [x.id for x in sc.runs if x.instance == r.instance].index(r.id)
            row = mine.iloc[k]
            got = data[data.data_id == r.data_id]
            assert got.evaluations.iloc[0] == 1 and got.evaluations.iloc[-1] <= row.budget
            assert got.evaluations.iloc[-1] == r.evals
            assert got.raw_y.iloc[-1] == row.fitness or got.raw_y.iloc[-1] == pytest.approx(row.fitness, rel=1e-9)
            checked += 1
    assert checked == len(runs)
    index = json.loads(next(out.glob("exact/IOHprofiler_f1_*.json")).read_text())
    info = json.loads(index["algorithm"]["info"])
    assert info["track"] == "exact" and info["name"] == "exact"
    assert index["scenarios"][0]["dimension"] == 3 and index["function_name"] == "mao2017-3rps"


def test_a_mixed_tree_of_an_experiment_and_a_suite_exports_both(suite, tmp_path, fkopt_run):
    import shutil
    from fkopt.kinds.experiment.config import ExperimentConfig
    from fkopt.kinds.experiment.reports import write_experiment
    from fkopt.kinds.experiment.runner import run_experiment
    _, folder = suite
    root = tmp_path / "results"
    shutil.copytree(folder, root / "kinbench" / "tiny")
    write_experiment(run_experiment(ExperimentConfig(
        name="e", paper="demo", mechanism={"name": "3-rps"}, cases=[{"pose": {"alpha": 9, "beta": 13, "z": 622}}],
        algorithms=[{"name": "pso"}], iterations=5, runs=2)), root)
    out = tmp_path / "ioh"
    assert fkopt_run("export", root, "--out", out).returncode == 0
    names = {json.loads(p.read_text())["function_name"]: json.loads(p.read_text())["function_id"]
             for p in out.glob("pso/*.json")}
    assert names == {"demo_e": 1, "mao2017-3rps": 2, "wu2015-3ppr": 3}    # folders sorted by path


def test_budget_trace_cuts_at_the_budget_and_opens_every_run_at_evaluation_1():
    evals = np.array([[20, 40, 60], [300, 300, 300], [5, 9, 12]])
    hist = np.array([[9.0, 4.0, 1.0], [1e-20, 1e-20, 1e-20], [3.0, 3.0, 2.0]])
    events = (np.array([0, 0, 0, 0, 1, 2, 2]), np.array([1, 13, 27, 55, 300, 5, 11]),
              np.array([9.0, 5.0, 4.0, 1.0, 1e-20, 3.0, 2.0]))
    r, e, f = budget_trace(events, evals, 50)
    assert r.tolist() == [0, 0, 0, 0, 1, 1, 2, 2, 2, 2]
    # run 0 cut at 40 (iteration 1), closed there; run 1 has no answer within B: 1 and B; run 2's
    # first value comes at 5: opened at 1 with inf, closed at its final count 12
    assert e.tolist() == [1, 13, 27, 40, 1, 50, 1, 5, 11, 12]
    assert f.tolist() == [9.0, 5.0, 4.0, 4.0, np.inf, np.inf, np.inf, 3.0, 2.0, 2.0]
    m = at_budget(hist, evals, 50, [1e-2])
    ends = np.r_[np.flatnonzero(r[1:] != r[:-1]), len(r) - 1]
    assert f[ends].tolist() == m["fitness"].tolist()


def _spoil_trace(folder, change):
    t = pd.read_csv(folder / "trace.csv.gz")
    change(t).to_csv(folder / "trace.csv.gz", index=False, compression="gzip")


@pytest.mark.parametrize("case,spoil,fragments", [
    ("no trace", lambda d: (d / "trace.csv.gz").unlink(), ["no trace.csv.gz", "rerun the suite"]),
    ("garbage", lambda d: (d / "trace.csv.gz").write_bytes(b"\x1f\x8bnope" * 9), ["trace.csv.gz", "not a valid gzip"]),
    ("run missing", lambda d: _spoil_trace(d, lambda t: t[t.solver != "lm"]),
     ["trace.csv.gz", "no rows for run 0 of solver 'lm', problem 'mao2017-3rps', set 'uniform', pose 0"]),
    ("column missing", lambda d: _spoil_trace(d, lambda t: t.drop(columns="pose")), ["missing column(s) pose"]),
    ("meta without problems", lambda d: (d / "meta.json").write_text(json.dumps(
        {**json.loads((d / "meta.json").read_text()), "config": {"kind": "suite", "name": "x"}})),
     ["meta.json", "'problems'"]),
])
def test_export_of_a_damaged_suite_is_one_line(suite, tmp_path, case, spoil, fragments, fkopt_run):
    import shutil
    _, folder = suite
    bad = tmp_path / "results" / "bad"
    shutil.copytree(folder, bad)
    spoil(bad)
    proc = fkopt_run("export", tmp_path / "results", "--out", tmp_path / "out")
    assert_one_line_error(proc, *fragments)
    assert proc.returncode == 2 and not (tmp_path / "out").exists()
