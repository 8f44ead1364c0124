"""Run traces in results folders and the IOHprofiler export read back."""
import json

import numpy as np
import pandas as pd
import pytest

from fkopt.experiment.config import ExperimentConfig
from fkopt.experiment.reports import write_experiment
from fkopt.experiment.runner import run_experiment
from fkopt.experiment.traces import read_trace, run_trace
from fkopt.export import MARKER, ioh_export, read_ioh
from test_cli import assert_one_line_error, cli

CONFIG = {
    "name": "ioh_demo", "paper": "demo", "mechanism": {"name": "3-rps"},
    "cases": [{"label": "a", "pose": {"alpha": 9, "beta": 13, "z": 622}},
              {"label": "b", "pose": {"alpha": -5, "beta": 4, "z": 580}}],
    "algorithms": [{"name": "gabc"}, {"name": "scipy:differential_evolution", "label": "scipy-de",
                                      "params": {"polish": False}}],
    "population": 10, "iterations": 40, "runs": 3, "seed": 3, "threshold": 1e-8,
}


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    root = tmp_path_factory.mktemp("results")
    er = run_experiment(ExperimentConfig(**CONFIG))
    return root, write_experiment(er, root), er


def test_run_trace_keeps_improvements_and_the_final_count():
    hist = np.array([[5.0, 5.0, 3.0, 3.0, 1.0, 1.0]])
    evals = np.array([[10, 20, 30, 40, 50, 60]])
    r, it, e, f = run_trace(hist, evals)
    assert e.tolist() == [10, 30, 50, 60] and f.tolist() == [5.0, 3.0, 1.0, 1.0]
    assert it.tolist() == [0, 2, 4, 5]
    r, it, e, f = run_trace(hist, evals, done=np.array([2]))    # stopped at iteration 2
    assert e.tolist() == [10, 30] and it.tolist() == [0, 2]


def test_trace_file_matches_the_runs(stored):
    _, folder, er = stored
    trace = read_trace(folder)
    runs = pd.read_csv(folder / "runs.csv")
    last = trace.groupby(["case", "algorithm", "run"], sort=False).tail(1)
    merged = last.merge(runs, on=["case", "algorithm", "run"])
    assert len(merged) == len(runs) == 2 * 2 * 3
    np.testing.assert_allclose(merged.best_fitness, merged.final_fitness, rtol=1e-9)
    assert (merged.evaluations_x == merged.evaluations_y).all()
    for _, g in trace.groupby(["case", "algorithm", "run"]):
        assert (np.diff(g.best_fitness.to_numpy())[:-1] < 0).all()      # improvements only
        assert (np.diff(g.evaluations.to_numpy()) > 0).all()


def test_ioh_export_reads_back(stored, tmp_path):
    root, folder, er = stored
    proc = cli("export", str(root), "--format", "ioh", "--out", str(tmp_path / "ioh"))
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "ioh"
    assert (out / MARKER).is_file()
    index = json.loads((out / "gabc" / "IOHprofiler_f1_demo_ioh_demo.json").read_text())
    assert index["function_id"] == 1 and index["maximization"] is False and index["suite"] == "fkopt"
    sc = index["scenarios"][0]
    assert sc["dimension"] == 3 and sc["path"] == "data_f1_demo_ioh_demo/IOHprofiler_f1_DIM3.dat"
    assert (out / "gabc" / sc["path"]).read_text().startswith("evaluations raw_y\n")
    data = read_ioh(out)
    runs = pd.read_csv(folder / "runs.csv")
    assert set(k[0] for k in data) == {"gabc", "scipy-de"}
    for (algo, fname, instance), entries in data.items():
        case = ["a", "b"][instance - 1]
        rows = runs[(runs.algorithm == algo) & (runs.case == case)].sort_values("run")
        assert len(entries) == 3
        for (block, run), (_, row) in zip(entries, rows.iterrows()):
            assert run["run_id"] == row["run"]
            assert block[-1, 0] == row["evaluations"] == run["evals"]          # ends at the final count
            assert block[-1, 1] == pytest.approx(row["final_fitness"], rel=1e-9)
            assert run["best"]["y"] == pytest.approx(row["final_fitness"], rel=1e-9)
            assert run["best"]["x"] == pytest.approx([row["x_alpha"], row["x_beta"], row["x_z"]], rel=1e-9)
            assert np.all(np.diff(block[:, 0]) > 0) and np.all(np.diff(block[:-1, 1]) < 0)
    # the export is repeatable over its own folder, never over stored results or strangers
    assert cli("export", str(folder), "--out", str(out)).returncode == 0
    assert_one_line_error(cli("export", str(root), "--out", str(root / "x")), "must lie outside the results")
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "keep.txt").write_text("x")
    assert_one_line_error(cli("export", str(root), "--out", str(tmp_path / "other")), "not written by fkopt export")
    assert_one_line_error(cli("export", str(root), "--format", "csv", "--out", str(tmp_path / "y")),
                          "unknown format 'csv'; allowed: ioh")
    assert_one_line_error(cli("export", str(tmp_path / "nothing"), "--out", str(tmp_path / "z")), "not a results folder")


def test_summary_table_is_not_cut_in_a_pipe(tmp_path):
    import yaml
    cfg = dict(CONFIG, name="wide", iterations=5, runs=2)
    cfg["cases"] = CONFIG["cases"][:1]
    path = tmp_path / "wide.yaml"
    path.write_text(yaml.safe_dump(cfg))
    proc = cli("run", str(path), "--out", str(tmp_path / "out"))
    assert proc.returncode == 0, proc.stderr
    assert "…" not in proc.stdout and "scipy-de" in proc.stdout and "success" in proc.stdout
