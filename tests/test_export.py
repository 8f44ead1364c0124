"""Run traces in results folders, exact evaluation counts, and the IOHprofiler export checked
against the IOHprofiler project's own artefacts: the files ``ioh.logger.Analyzer`` writes and
``iohinspector``'s reader."""
import gzip
import json
import warnings
import zlib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from conftest import Sphere
from fkopt.kinds.experiment.config import ExperimentConfig
from fkopt.kinds.experiment.reports import write_experiment
from fkopt.kinds.experiment.runner import run_experiment
from fkopt.run.trace import MAX_BYTES, read_trace, run_trace
from fkopt.tools.export import ATTRIBUTES, MARKER
from fkopt.solve import solve
from test_cli import assert_one_line_error

CONFIG = {
    "name": "ioh_demo", "paper": "demo", "mechanism": {"name": "3-rps"},
    "cases": [{"label": "a", "pose": {"alpha": 9, "beta": 13, "z": 622}},
              {"label": "b", "pose": {"alpha": -5, "beta": 4, "z": 580}}],
    "algorithms": [{"name": "gabc"}, {"name": "pso"}, {"name": "lm"},
                   {"name": "scipy:differential_evolution", "label": "scipy-de", "params": {"polish": False}},
                   {"name": "scipy:dual_annealing", "label": "scipy-da"}],
    "population": 10, "iterations": 40, "runs": 3, "seed": 3, "threshold": 1e-4, "stop_at_threshold": True,
}


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    root = tmp_path_factory.mktemp("results")
    er = run_experiment(ExperimentConfig(**CONFIG))
    return root, write_experiment(er, root), er


# -- exact evaluation counts -------------------------------------------------------------------
class Recording:
    """A problem that keeps every fitness value it computes, in call order (outside fkopt's
    bookkeeping: what a run really evaluated)."""

    def __init__(self, problem):
        self.problem, self.values = problem, []

    def __getattr__(self, name):
        return getattr(self.problem, name)

    def fitness(self, x):
        f = self.problem.fitness(x)
        self.values.append(np.ravel(f).copy())
        return f


def expected_events(values):
    """Every improvement of the best-so-far over ``values`` (evaluation numbers from 1), the
    first evaluation always included."""
    v = np.where(np.isnan(values), np.inf, values)
    best = np.minimum.accumulate(v)
    keep = np.r_[True, best[1:] < best[:-1]]
    return np.flatnonzero(keep) + 1, v[keep]


@pytest.mark.parametrize("algorithm", ["abc", "gabc", "pso", "aco", "pabc", "scipy:differential_evolution",
                                       "scipy:dual_annealing"])
def test_improvements_carry_their_exact_evaluation(algorithm):
    """Batched runs (several rows, stopping at a target) report every improvement at the
    evaluation a run alone, counted by a recording problem, made it -- and use as many."""
    problem, runs = Sphere(dim=3), 4
    kw = dict(population=10, iterations=60, seed=5)
    target = float(np.median(solve(problem, algorithm, runs=runs, **kw).fitness))   # some runs reach it
    kw.update(target=target, stop_at_target=True)
    res = solve(problem, algorithm, runs=runs, **kw)
    r, e, f = res.events
    assert np.isfinite(res.evaluations_to(target)).any()       # some runs stopped at the target
    for k in range(runs):
        rec = Recording(Sphere(dim=3))
        alone = solve(rec, algorithm, runs=1, run_ids=[k], **kw)
        want_e, want_f = expected_events(np.concatenate(rec.values))
        assert e[r == k].tolist() == want_e.tolist()
        assert f[r == k].tolist() == want_f.tolist()
        used = sum(len(v) for v in rec.values)
        assert res.evaluations[k] == alone.evaluations[0] == used
        assert res.fitness[k] == want_f[-1]                     # the final fitness is an event
        hit = np.flatnonzero(want_f < target)
        expect = want_e[hit[0]] if hit.size else np.nan
        np.testing.assert_equal(res.evaluations_to(target)[k], expect)


def test_run_trace_closes_each_run_at_its_final_count():
    events = (np.array([0, 0, 0, 1]), np.array([1, 13, 27, 1]), np.array([5.0, 3.0, 1.0, 2.0]))
    evals = np.array([[10, 20, 30, 40], [10, 20, 30, 40]])
    r, it, e, f = run_trace(events, evals)
    assert r.tolist() == [0, 0, 0, 0, 1, 1] and e.tolist() == [1, 13, 27, 40, 1, 40]
    assert it.tolist() == [0, 1, 2, 3, 0, 3] and f.tolist() == [5.0, 3.0, 1.0, 1.0, 2.0, 2.0]
    r, it, e, f = run_trace(events, evals, done=np.array([2, 0]))    # stopped at iterations 2 and 0
    assert e.tolist() == [1, 13, 27, 30, 1, 10] and it.tolist() == [0, 1, 2, 2, 0, 0]


def test_trace_file_matches_the_runs(stored):
    _, folder, er = stored
    trace = read_trace(folder)
    runs = pd.read_csv(folder / "runs.csv")
    trace["case"], trace["algorithm"] = trace["case"].astype(str), trace["algorithm"].astype(str)
    last = trace.groupby(["case", "algorithm", "run"], sort=False).tail(1)
    merged = last.merge(runs, on=["case", "algorithm", "run"])
    assert len(merged) == len(runs) == 2 * 5 * 3
    np.testing.assert_allclose(merged.best_fitness, merged.final_fitness, rtol=1e-9)
    assert (merged.evaluations_x == merged.evaluations_y).all()
    for _, g in trace.groupby(["case", "algorithm", "run"]):
        assert g.evaluations.iloc[0] == 1
        assert (np.diff(g.best_fitness.to_numpy()) <= 0).all()    # improvements (to the 10 digits stored)
        assert (np.diff(g.evaluations.to_numpy()) > 0).all()
    first = trace[trace.best_fitness < CONFIG["threshold"]].groupby(["case", "algorithm", "run"]).evaluations.min()
    hit = runs.dropna(subset=["evaluations_to_threshold"]).set_index(["case", "algorithm", "run"])
    assert len(hit) and (first.loc[hit.index] == hit.evaluations_to_threshold).all()


# -- the export, against the ioh package's own logger and iohinspector's reader ------------------
def _analyzer_reference(tmp_path):
    """What ``ioh.logger.Analyzer`` writes for a tiny problem: its index and .dat files."""
    import ioh          # a test dependency (pyproject: test extra): fail, never skip, without it
    problem = ioh.get_problem(1, instance=1, dimension=3)
    logger = ioh.logger.Analyzer(root=str(tmp_path), folder_name="ref", algorithm_name="rs",
                                 algorithm_info="", store_positions=False)
    logger.add_experiment_attribute("variables", "a b c")
    problem.attach_logger(logger)
    rng = np.random.default_rng(1)
    for _ in range(2):
        for _ in range(8):
            problem(rng.uniform(-5, 5, 3))
        problem.reset()
    logger.close()
    index = next((tmp_path / "ref").glob("*.json"))
    return json.loads(index.read_text()), index


def test_ioh_export_has_the_analyzer_layout_and_loads_in_iohinspector(stored, tmp_path, fkopt_run):
    import iohinspector  # a test dependency (pyproject: test extra)
    root, folder, er = stored
    out = tmp_path / "ioh"
    proc = fkopt_run("export", str(root), "--format", "ioh", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    assert (out / MARKER).is_file() and not list(out.glob("*.json")) and not list(out.rglob("*.info"))
    ref, ref_file = _analyzer_reference(tmp_path / "ref")
    indexes = sorted(out.glob("*/IOHprofiler_f*.json"))
    assert len(indexes) == 5
    for index_file in indexes:
        index = json.loads(index_file.read_text())
        assert list(index) == list(ref)                                  # the same keys, in order
        assert index["attributes"] == ref["attributes"] == ATTRIBUTES
        assert set(index["algorithm"]) == set(ref["algorithm"])
        sc, ref_sc = index["scenarios"][0], ref["scenarios"][0]
        assert set(sc) == set(ref_sc) and set(sc["runs"][0]) == set(ref_sc["runs"][0])
        assert set(sc["runs"][0]["best"]) == set(ref_sc["runs"][0]["best"])
        assert all(len(a) == 1 and isinstance(next(iter(a.values())), str) for a in index["experiment_attributes"])
        dat = (index_file.parent / sc["path"]).read_text()
        assert dat.startswith(" ".join(ATTRIBUTES) + "\n1 ")
    assert (ref_file.parent / ref["scenarios"][0]["path"]).read_text().startswith(" ".join(ATTRIBUTES) + "\n1 ")

    with warnings.catch_warnings():     # iohinspector warns (and skips) on a file it cannot read
        warnings.simplefilter("error")
        dm = iohinspector.DataManager()
        dm.add_folder(str(out))
    overview = dm.overview.to_pandas()
    runs = pd.read_csv(folder / "runs.csv")
    assert len(dm.data_sets) == 5 and len(overview) == len(runs) == 30      # every run, nothing else
    data = dm.load(monotonic=True).to_pandas()
    trace = read_trace(folder)
    trace["case"], trace["algorithm"] = trace["case"].astype(str), trace["algorithm"].astype(str)
    cases = list(dict.fromkeys(runs.case))
    checked = 0
    for ds in dm.data_sets:
        for run in ds.scenarios[0].runs:
            case = cases[run.instance - 1]
            ids = sorted(runs[(runs.algorithm == ds.algorithm.name) & (runs.case == case)].run)
            run_id = ids[[r.id for r in ds.scenarios[0].runs if r.instance == run.instance].index(run.id)]
            t = trace[(trace.algorithm == ds.algorithm.name) & (trace.case == case) & (trace.run == run_id)]
            got = data[data.data_id == run.data_id]
            # best-so-far at every evaluation that either side lists must agree
            grid = np.union1d(t.evaluations, got.evaluations)
            mine = t.best_fitness.to_numpy()[np.searchsorted(t.evaluations, grid, side="right") - 1]
            theirs = got.raw_y.to_numpy()[np.searchsorted(got.evaluations, grid, side="right") - 1]
            np.testing.assert_allclose(theirs, mine, rtol=1e-9)
            assert run.evals == t.evaluations.iloc[-1] and run.best.y == pytest.approx(t.best_fitness.iloc[-1], rel=1e-9)
            checked += 1
    assert checked == 30


def test_export_refuses_what_it_must_not_touch(stored, tmp_path, fkopt_run):
    root, folder, er = stored
    out = tmp_path / "ioh"
    assert fkopt_run("export", str(root), "--out", str(out)).returncode == 0
    assert fkopt_run("export", str(folder), "--out", str(out)).returncode == 0       # over its own folder
    (tmp_path / "legacy").mkdir()
    (tmp_path / "legacy" / "fkopt-export.json").write_text("{}")               # an older release's export
    assert fkopt_run("export", str(folder), "--out", str(tmp_path / "legacy")).returncode == 0
    assert not (tmp_path / "legacy" / "fkopt-export.json").exists()
    assert_one_line_error(fkopt_run("export", str(root), "--out", str(root / "x")), "must lie outside the results")
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "keep.txt").write_text("x")
    assert_one_line_error(fkopt_run("export", str(root), "--out", str(tmp_path / "other")), "not written by fkopt export")
    assert_one_line_error(fkopt_run("export", str(root), "--format", "csv", "--out", str(tmp_path / "y")),
                          "unknown format 'csv'; allowed: ioh")
    assert_one_line_error(fkopt_run("export", str(tmp_path / "nothing"), "--out", str(tmp_path / "z")), "not a results folder")


# -- hostile inputs (issue 19): one line naming the file, non-zero exit, nothing written ---------
def _copy(folder, dest):
    import shutil
    shutil.copytree(folder, dest)
    return dest


def _bomb(path, unpacked: int):
    """A small gzip of a valid-looking trace that unpacks to ``unpacked`` bytes (streamed)."""
    line = b"a,gabc,0,0,1,1.0\n"
    block = line * (1 << 16)
    comp = zlib.compressobj(9, zlib.DEFLATED, 31)
    with open(path, "wb") as fh:
        fh.write(comp.compress(b"case,algorithm,run,iteration,evaluations,best_fitness\n"))
        for _ in range(unpacked // len(block) + 1):
            fh.write(comp.compress(block))
        fh.write(comp.flush())


HOSTILE = {
    "garbage gzip": (lambda d: (d / "trace.csv.gz").write_bytes(b"\x1f\x8bnot really gzip" * 10),
                     ["trace.csv.gz", "not a valid gzip"]),
    "not gzip at all": (lambda d: (d / "trace.csv.gz").write_text("case,algorithm\n"),
                        ["trace.csv.gz", "not a valid gzip"]),
    "truncated gzip": (lambda d: (d / "trace.csv.gz").write_bytes((d / "trace.csv.gz").read_bytes()[:300]),
                       ["trace.csv.gz", "truncated gzip"]),
    "rows missing": (lambda d: _rewrite(d, lambda t: t[t.algorithm != "pso"]),
                     ["trace.csv.gz", "no rows for run 0 of algorithm 'pso'"]),
    "non-numeric fitness": (lambda d: _rewrite(d, lambda t: t.assign(best_fitness=t.best_fitness.astype(object))
                                               .pipe(_set, 4, "best_fitness", "abc")),
                            ["trace.csv.gz", "row 5 column best_fitness: 'abc' is not a number"]),
    "non-numeric evaluations": (lambda d: _rewrite(d, lambda t: t.assign(evaluations=t.evaluations.astype(object))
                                                   .pipe(_set, 2, "evaluations", "x2")),
                                ["trace.csv.gz", "row 3 column evaluations", "not an integer >= 1"]),
    "column missing": (lambda d: _rewrite(d, lambda t: t.drop(columns="iteration")),
                       ["trace.csv.gz", "missing column(s) iteration"]),
    "meta without mechanism": (lambda d: (d / "meta.json").write_text(json.dumps(
        {k: v for k, v in json.loads((d / "meta.json").read_text()).items() if k != "mechanism"})),
        ["meta.json", "no 'mechanism'"]),
    "meta not json": (lambda d: (d / "meta.json").write_text("{oops"), ["meta.json", "cannot read"]),
    # the experiment's own loader (Kind.ioh_functions) names what is missing and what to do
    "no trace": (lambda d: (d / "trace.csv.gz").unlink(), ["no trace.csv.gz", "rerun the experiment to export it"]),
    # a kind no registered Kind answers to: one line, not the experiment's loader by default
    "unknown kind": (lambda d: (d / "meta.json").write_text(json.dumps(
        {**json.loads((d / "meta.json").read_text()), "kind": "board\n" + "x" * 80})),
        ["meta.json", "kind 'board x", "is not one this fkopt knows"]),
    "decompression bomb": (lambda d: _bomb(d / "trace.csv.gz", MAX_BYTES + (1 << 20)),
                           ["trace.csv.gz", f"unpacks to more than {MAX_BYTES // 1024 ** 2} MB"]),
}


def _rewrite(folder, change):
    t = pd.read_csv(folder / "trace.csv.gz")
    change(t).to_csv(folder / "trace.csv.gz", index=False, compression="gzip")


def _set(t, i, col, value):
    t.iloc[i, t.columns.get_loc(col)] = value
    return t


@pytest.mark.parametrize("case", list(HOSTILE))
def test_export_of_hostile_results_is_one_line_and_writes_nothing(stored, tmp_path, case, fkopt_run):
    root, folder, er = stored
    bad = _copy(folder, tmp_path / "results" / "bad")
    spoil, fragments = HOSTILE[case]
    spoil(bad)
    out = tmp_path / "out"
    proc = fkopt_run("export", str(tmp_path / "results"), "--out", str(out))
    assert_one_line_error(proc, *fragments)
    assert proc.returncode == 2
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["results"]


def test_bomb_is_measured_not_unpacked_into_memory(tmp_path):
    """The cap is found by streaming: a trace just past it is refused by read_trace itself."""
    _bomb(tmp_path / "trace.csv.gz", 3 << 20)
    from fkopt.errors import FkoptError
    with pytest.raises(FkoptError, match="unpacks to more than 2 MB"):
        read_trace(tmp_path, limit=2 << 20)
    assert len(read_trace(tmp_path, limit=4 << 20)) > 100_000
    with gzip.open(tmp_path / "trace.csv.gz", "rb") as fh:
        assert fh.read(8) == b"case,alg"


def test_an_eof_anywhere_is_an_error_not_an_interruption(monkeypatch, capsys, tmp_path):
    """click turns an EOFError into Abort ("interrupted", 130); fkopt says what it is instead."""
    import sys

    import fkopt.tools.export
    from fkopt.cli import main

    def truncated(*args, **kwargs):
        raise EOFError("Compressed file ended before the end-of-stream marker was reached")
    monkeypatch.setattr(fkopt.tools.export, "ioh_export", truncated)
    monkeypatch.setattr(sys, "argv", ["fkopt", "export", str(tmp_path), "--out", str(tmp_path / "o")])
    with pytest.raises(SystemExit) as exc:
        main()
    err = capsys.readouterr().err.strip()
    assert exc.value.code == 2 and len(err.splitlines()) == 1
    assert err.startswith("fkopt: error: unexpected end of a file") and "end-of-stream" in err


def test_check_refuses_a_stored_gzip_bomb_in_one_line(tmp_path, cli, monkeypatch):
    """fkopt check (and report) read stored .csv.gz files through the same cap as the export."""
    import fkopt.files.reading
    monkeypatch.setattr(fkopt.files.reading, "MAX_UNPACKED", 2 << 20)     # the module that reads the bound
    stored = Path(__file__).resolve().parents[1] / "results" / "mao2017" / "tab6"
    folder = _copy(stored, tmp_path / "results" / "mao2017" / "tab6")
    _bomb(folder / "trace.csv.gz", 3 << 20)
    code, _, err = cli("check", tmp_path / "results", "-q")
    assert code != 0 and "trace.csv.gz" in err and "unpacks to more than 2 MB" in err, err
    assert "Traceback" not in err
