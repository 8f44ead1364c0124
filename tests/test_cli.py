"""CLI: JSON outputs, one-line errors, and `fkopt run` writing every promised file."""
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

@pytest.fixture
def fkopt(fkopt_run):
    """``fkopt ARGS`` in this process (conftest's ``fkopt_run``, read like subprocess.run): these tests
    check outputs, files and exit statuses, not the interpreter's start-up."""
    return fkopt_run


def assert_one_line_error(proc, *fragments):
    assert proc.returncode != 0
    assert proc.stdout == "" or "Traceback" not in proc.stdout
    err = proc.stderr.strip()
    assert "Traceback" not in err
    assert len(err.splitlines()) == 1, err
    assert err.startswith("fkopt: error: ")
    for f in fragments:
        assert f in err, err


def test_list_json(fkopt):
    out = json.loads(fkopt("list", "--json").stdout)
    assert {"3-rps"} <= set(out["mechanisms"])
    assert {"abc", "gabc"} <= set(out["algorithms"])


def test_ik_json_matches_spec(fkopt):
    out = json.loads(fkopt("ik", "3-rps", "--pose", "alpha=9,beta=13,z=622", "--json").stdout)
    np.testing.assert_allclose([out["joints"][k] for k in ("d1", "d2", "d3")],
                               [598.8458, 671.9171, 629.1616], atol=5e-5)


def test_fk_json_recovers_pose(fkopt):
    proc = fkopt("fk", "3-rps", "--joints", "d1=598.84582586,d2=671.91712863,d3=629.16156603", "--json")
    out = json.loads(proc.stdout)
    np.testing.assert_allclose([out["pose"][k] for k in ("alpha", "beta", "z")], [9, 13, 622], atol=1e-5)
    assert out["fitness"] < 1e-10


def test_fk_reports_unreachable_joints(fkopt):
    proc = fkopt("fk", "3-rps", "--joints", "d1=100,d2=900,d3=600", "--json")
    assert_one_line_error(proc, "no pose within the bounds reproduces these joints", "best residual")


def test_errors_are_one_line(fkopt):
    assert_one_line_error(fkopt("ik", "nope", "--pose", "a=1"), "unknown mechanism 'nope'", "3-rps")
    assert_one_line_error(fkopt("ik", "3-rps", "--pose", "alpha=9,beta=13"), "missing z")
    assert_one_line_error(fkopt("ik", "3-rps", "--pose", "alpha=x"), "needs a number")
    assert_one_line_error(fkopt("fk", "3-rps", "--joints", "d1=1,d2=2,d3=3", "--algorithm", "zzz"),
                          "unknown algorithm 'zzz'", "gabc")
    assert_one_line_error(fkopt("frobnicate"), "No such command")


SMALL = {
    "name": "small", "paper": "test", "title": "small test",
    "mechanism": {"name": "3-rps"},
    "cases": [{"pose": {"alpha": 9, "beta": 13, "z": 622}, "printed": {"gabc": {"alpha": 9.0}}}],
    "algorithms": [{"name": "abc", "printed": {"mean_fitness": 1e-17, "time_ms": 300}},
                   {"name": "gabc"}],
    "population": 10, "iterations": 40, "runs": 4, "seed": 1, "threshold": 1e-3,
}


def write_config(tmp_path, data, name="exp.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def test_run_writes_all_files(tmp_path, fkopt):
    cfg = write_config(tmp_path, SMALL)
    proc = fkopt("run", str(cfg), "--out", str(tmp_path / "res"), "--quiet")
    assert proc.returncode == 0, proc.stderr
    folder = tmp_path / "res" / "test" / "small"
    for name in ("summary.csv", "timing.csv", "values.csv", "runs.csv", "convergence.csv",
                 "convergence.png", "meta.json"):
        assert (folder / name).stat().st_size > 0, name
    import pandas as pd
    summary = pd.read_csv(folder / "summary.csv")
    assert list(summary["algorithm"]) == ["abc", "gabc"]
    assert {"mean_fitness", "std_fitness", "best_fitness", "worst_fitness", "median_fitness",
            "mean_evaluations", "success_rate", "printed_mean_fitness"} <= set(summary.columns)
    timing = pd.read_csv(folder / "timing.csv")
    assert timing.loc[0, "printed_time_ms"] == 300
    runs = pd.read_csv(folder / "runs.csv")
    assert len(runs) == 8
    meta = json.loads((folder / "meta.json").read_text())
    assert meta["seed"] == 1 and meta["config"]["runs"] == 4
    assert "libraries" not in meta and "platform" not in meta      # environment: env.json
    assert set(meta["files"]) == {"summary.csv", "values.csv", "runs.csv", "trace.csv.gz", "convergence.csv"}
    env = json.loads((folder / "env.json").read_text())
    assert "numpy" in env["libraries"] and env["fkopt_version"] and env["fingerprint"]["machine"]
    assert not [p for p in (tmp_path / "res" / "test").iterdir() if p.name.startswith(".")]


def test_run_is_deterministic(tmp_path, fkopt):
    """The same bytes twice, the second time with each algorithm's task in a worker process
    (rebuilt there from the config, not the live objects of this process)."""
    cfg = write_config(tmp_path, SMALL)
    for out, jobs in (("a", "1"), ("b", "2")):
        assert fkopt("run", str(cfg), "--out", str(tmp_path / out), "--quiet", "--jobs", jobs).returncode == 0
    for name in ("summary.csv", "values.csv", "runs.csv", "convergence.csv"):
        a = (tmp_path / "a" / "test" / "small" / name).read_bytes()
        b = (tmp_path / "b" / "test" / "small" / name).read_bytes()
        assert a == b, name


@pytest.mark.parametrize("change,fragments", [
    ({"population": 1}, ["population", "greater than or equal to 2"]),
    ({"iterations": 0}, ["iterations", "greater than or equal to 1"]),
    ({"runs": 0}, ["runs"]),
    ({"mechanism": {"name": "4-rps"}}, ["unknown mechanism '4-rps'", "3-rps"]),
    ({"algorithms": [{"name": "bee"}]}, ["unknown algorithm 'bee'", "gabc"]),
    ({"algorithms": [{"name": "abc", "params": {"limit": -1}}]}, ["'limit'", "parameters: limit"]),
    ({"algorithms": [{"name": "abc", "colour": 1}]}, ["algorithms[0].colour", "unknown field"]),
    ({"mechanism": {"name": "3-rps", "bounds": {"z": [700, 400]}}}, ["bounds.z", "lower 700"]),
    ({"cases": [{"pose": {"alpha": 9, "beta": 13, "z": 900}}]}, ["cases[0].pose", "z=900", "[400, 700]"]),
    ({"cases": [{"pose": {"alpha": 9, "beta": 13}}]}, ["missing z"]),
    ({"stop_at_threshold": True, "threshold": None}, ["stop_at_threshold needs a threshold"]),
])
def test_config_errors(tmp_path, change, fragments, fkopt):
    data = {**SMALL, **change}
    if data.get("threshold") is None:
        data.pop("threshold")
    cfg = write_config(tmp_path, data)
    proc = fkopt("run", str(cfg), "--out", str(tmp_path / "res"), "--quiet")
    assert_one_line_error(proc, str(cfg), *fragments)
    assert not (tmp_path / "res").exists() or not any((tmp_path / "res").rglob("*.csv"))


def test_malformed_yaml_names_line(tmp_path, fkopt):
    cfg = tmp_path / "bad.yaml"
    cfg.write_text("name: x\nmechanism: {name: 3-rps\nruns: 3\n")
    assert_one_line_error(fkopt("run", str(cfg), "--quiet"), "bad.yaml", "malformed YAML at line")


def test_missing_file(fkopt):
    assert_one_line_error(fkopt("run", "/nonexistent/x.yaml", "--quiet"), "cannot read")


def test_stored_configs_validate():
    from fkopt.run.pipeline import load_any, validate_any
    root = Path(__file__).resolve().parents[1] / "configs"
    files = sorted(f for f in root.rglob("*.yaml") if f.name != "claims.yaml")   # claims are no config
    assert files
    from fkopt.kinds.assembly.kind import AssemblyConfig
    from fkopt.kinbench.config import SuiteConfig
    from fkopt.kinds.study.config import StudyConfig
    for f in files:   # experiments, studies (kind: study), assembly modes and suites
        cfg = load_any(f)
        tasks = validate_any(cfg)
        if isinstance(cfg, SuiteConfig):     # one task per (problem, solver) its subset runs, one per clock-track arm
            clock = cfg.tracks.clock if cfg.tracks is not None else None
            pairs = sum(cfg.runs_problem(s.key, p.name) for p in cfg.problems for s in cfg.solvers)
            assert pairs <= len(cfg.problems) * len(cfg.solvers) and (pairs < len(cfg.problems) * len(cfg.solvers)
                                                                       or not cfg.subsets), f
            branch = [t for t in (cfg.tracks.all_solutions, cfg.tracks.paths) if t is not None] \
                if cfg.tracks is not None else []      # one task per arm of the all-solutions and paths tracks
            assert tasks == pairs + (len(clock.problems) if clock else 0) + sum(len(t.problems) for t in branch), f
        elif isinstance(cfg, AssemblyConfig):
            assert tasks == 1, f
        elif isinstance(cfg, StudyConfig):   # every algorithm on every pose block
            assert tasks > 0 and tasks % len(cfg.algorithms) == 0, f
        else:    # one task per algorithm, solving every case, and one timing task per timed case
            from fkopt.run.timing import TIMING_RUNS
            cases = cfg.cases.random if hasattr(cfg.cases, "random") else len(cfg.cases)
            assert tasks == len(cfg.algorithms) + min(cases, TIMING_RUNS), f
