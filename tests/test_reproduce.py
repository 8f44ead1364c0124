"""Regression on stored results (`fkopt check`), its teeth, and the generated report."""
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from fkopt.reproduce import PAPERS
from fkopt.reproduce.check import check_experiment, select
from fkopt.reproduce.report import build_report
from fkopt.reproduce.store import Store

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "results"
STORED = select(Store(RESULTS), "ci")


def test_every_paper_has_stored_results():
    papers = {e.paper for e in Store(RESULTS).experiments()}
    assert set(PAPERS) <= papers, f"missing results for {set(PAPERS) - papers}"


@pytest.mark.parametrize("exp", STORED, ids=[f"{e.paper}/{e.name}" for e in STORED])
def test_stored_results_are_reproduced(exp):
    mismatches = check_experiment(exp)
    assert not mismatches, "\n".join(map(str, mismatches[:10]))


def _tampered_copy(tmp_path, paper, name, edit):
    src = RESULTS / paper / name
    dst = tmp_path / "results" / paper / name
    shutil.copytree(src, dst)
    meta = json.loads((dst / "meta.json").read_text())
    edit(meta["config"])
    (dst / "meta.json").write_text(json.dumps(meta))
    return tmp_path / "results"


def _set_params(algo, **params):
    def edit(cfg):
        for a in cfg["algorithms"]:
            if a["name"] == algo:
                a["params"] = {**a.get("params", {}), **params}
    return edit


def test_check_has_teeth(tmp_path):
    # ABC with limit 1 abandons every source after one failed trial: a different algorithm.
    root = _tampered_copy(tmp_path, "mao2017", "tab4_tab5_fig3", _set_params("abc", limit=1))
    exp = Store(root).get("mao2017", "tab4_tab5_fig3")
    bad = check_experiment(exp)
    assert bad, "a changed ABC limit must be detected"
    assert all(m.experiment == "mao2017/tab4_tab5_fig3" for m in bad)
    text = str(bad[0])
    assert "column '" in text and "stored" in text and "rerun" in text


def test_check_cli_fails_and_names_experiment_column_values(tmp_path):
    root = _tampered_copy(tmp_path, "mao2017", "tab4_tab5_fig3", _set_params("gabc", rule="zhu2010", C=0.2))
    proc = subprocess.run([sys.executable, "-m", "fkopt.cli", "check", str(root), "--quiet"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 1, proc.stderr          # drift: 1 (a user error would be 2)
    last = proc.stderr.strip().splitlines()[-1]
    assert last.startswith("fkopt: check failed:") and "mao2017/tab4_tab5_fig3" in last
    assert "column '" in last and "stored" in last and "rerun" in last


def test_report_is_generated_not_edited():
    report, _, index = build_report(RESULTS)
    assert (RESULTS / "REPORT.md").read_text() == report, "run `fkopt report results` after changing results"
    for paper in PAPERS:
        assert f"## {paper}" in report
    assert "**held**" in report
    assert set(index["paper"]) >= set(PAPERS)


# -- teeth per file kind (issue 10 point 7) ---------------------------------------------------------
def _copy(tmp_path, paper="mao2017", name="tab6"):
    dst = tmp_path / "results" / paper / name
    shutil.copytree(RESULTS / paper / name, dst)
    return dst


def _resign(folder):
    """Record the digests of the edited files, as if a drifted fkopt had written them."""
    from fkopt.run.compare import file_digests
    meta = json.loads((folder / "meta.json").read_text())
    meta["files"] = file_digests(folder)
    (folder / "meta.json").write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n")


def _edit_csv(folder, file, row, column, change):
    import pandas as pd
    path = folder / file
    df = pd.read_csv(path)
    df[column] = df[column].astype(float)
    df.loc[row, column] = change(df.loc[row, column])
    df.to_csv(path, index=False, float_format="%.10g")


EDITS = {   # file kind -> a small edit
    "summary.csv": lambda f: _edit_csv(f, "summary.csv", 0, "mean_fitness", lambda v: v * 1.0000001),
    "values.csv": lambda f: _edit_csv(f, "values.csv", 0, "median_run_value", lambda v: v + 1e-7),
    "runs.csv": lambda f: _edit_csv(f, "runs.csv", 3, "final_fitness", lambda v: v * 1.001),
    "convergence.csv": lambda f: _edit_csv(f, "convergence.csv", 7, "median", lambda v: v * 1.001),
}


def test_integrity_catches_any_edit_of_any_table(tmp_path):
    from fkopt.reproduce.check import integrity
    for file, edit in EDITS.items():
        folder = _copy(tmp_path / file)
        assert integrity(Store(folder.parents[1]).get("mao2017", "tab6")) == []
        edit(folder)
        bad = integrity(Store(folder.parents[1]).get("mao2017", "tab6"))
        assert [m.file for m in bad] == [file] and "SHA-256" in bad[0].rule


def test_exact_check_names_every_edited_file(tmp_path):
    folder = _copy(tmp_path)
    for edit in EDITS.values():
        edit(folder)
    meta = json.loads((folder / "meta.json").read_text())
    meta["objective"] = "absolute"                     # meta.json: a field the config fixes
    (folder / "meta.json").write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n")
    _resign(folder)                                    # digests agree: only the rerun can tell
    bad = check_experiment(Store(folder.parents[1]).get("mao2017", "tab6"), exact=True)
    byte = [m for m in bad if "byte-identical" in m.rule]
    assert {m.file for m in byte} == {*EDITS, "meta.json"}
    assert all("mao2017/tab6" in str(m) and "line" in m.row for m in byte)


@pytest.mark.parametrize("tier", ["blas", "any"])
def test_tolerances_catch_the_edits_of_issue_10(tmp_path, tier):
    """The cross-platform rules still catch mean fitness x5, success 1 -> 0.95, median
    iterations +18 %, mean evaluations +2 % with re-signed digests (runs/convergence edits: the
    digests, above): GABC's rows touch no BLAS, and summary.csv must hold the stored runs' statistics."""
    folder = _copy(tmp_path)
    _edit_csv(folder, "summary.csv", 0, "mean_fitness", lambda v: v * 5)
    _edit_csv(folder, "summary.csv", 1, "success_rate", lambda v: 0.95)
    _edit_csv(folder, "summary.csv", 2, "median_iterations_to_threshold", lambda v: v * 1.18)
    _edit_csv(folder, "summary.csv", 3, "mean_evaluations", lambda v: v * 1.02)
    _resign(folder)
    bad = check_experiment(Store(folder.parents[1]).get("mao2017", "tab6"), tier=tier)
    named = {(m.file, m.column) for m in bad}
    assert named == {("summary.csv", "mean_fitness"), ("summary.csv", "success_rate"),
                     ("summary.csv", "median_iterations_to_threshold"), ("summary.csv", "mean_evaluations")}


def test_unedited_copy_passes_both_modes(tmp_path):
    folder = _copy(tmp_path)
    exp = Store(folder.parents[1]).get("mao2017", "tab6")
    assert check_experiment(exp, exact=False) == []


def test_check_accepts_a_paper_folder(tmp_path):
    folder = _copy(tmp_path)
    proc = subprocess.run([sys.executable, "-m", "fkopt.cli", "check", str(folder.parent)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "ok   mao2017/tab6" in proc.stdout and "1 experiments match" in proc.stdout


def test_reproduce_in_worker_processes_gives_the_serial_files(tmp_path, cli):
    """--jobs 2 solves the experiments in two spawned worker processes, then times and writes them
    here: every deterministic file and the report equal those of --jobs 1."""
    import filecmp

    import yaml

    from fkopt.run.writers import deterministic_files
    configs = tmp_path / "configs" / "mini"
    configs.mkdir(parents=True)
    base = {"paper": "mini", "mechanism": {"name": "3-rps"}, "iterations": 30, "runs": 3, "seed": 4}
    (configs / "a.yaml").write_text(yaml.safe_dump({**base, "name": "a", "cases": {"random": 3, "seed": 1},
                                                    "algorithms": [{"name": "gabc"}, {"name": "pso"}]}))
    (configs / "b.yaml").write_text(yaml.safe_dump({**base, "name": "b",
                                                    "cases": [{"pose": {"alpha": 5, "beta": 3, "z": 600}}],
                                                    "algorithms": [{"name": "abc"}, {"name": "lm", "population": 1}]}))
    outs = {}
    for jobs in (1, 2):
        outs[jobs] = tmp_path / f"out{jobs}"
        code, _, err = cli("reproduce", "--configs", tmp_path / "configs", "--out", outs[jobs], "--jobs", jobs, "-q")
        assert code == 0, err
    for name in ("a", "b"):
        one, two = outs[1] / "mini" / name, outs[2] / "mini" / name
        files = deterministic_files(one)
        assert "summary.csv" in files and files == deterministic_files(two)
        assert (two / "timing_runs.csv").exists()          # timed here, after the workers
        for f in files:
            assert filecmp.cmp(one / f, two / f, shallow=False), f"{name}/{f}"
    assert (outs[1] / "REPORT.md").read_text() == (outs[2] / "REPORT.md").read_text()
    code, _, err = cli("reproduce", "--configs", tmp_path / "configs", "--out", outs[1], "--jobs", 0)
    assert code == 2 and "--jobs: must be at least 1" in err


# -- passes on any machine (issue 18): tiers, path-dependent rows, checks on every platform -------
def test_platform_tier_follows_what_decides_the_bits(monkeypatch):
    from fkopt.run import provenance
    here = provenance.fingerprint()
    assert provenance.platform_tier(dict(here)) == "exact"
    assert provenance.platform_tier({**here, "blas_runtime": "openblas 0.3.31 kernel=SkylakeX"}) == "blas"
    assert provenance.platform_tier({**here, "numpy_simd": "X86_V2"}) == "any"
    assert provenance.platform_tier({**here, "blas": "mkl", "numpy": "1.26.4"}) == "any"
    assert provenance.platform_tier(None) == "any"
    assert "cpu" not in here and "kernel=" in here["blas_runtime"] or here["blas_runtime"] in ("unknown", "none")


def test_only_fkopts_own_swarms_on_builtin_mechanisms_are_blas_free():
    from fkopt.registry import algorithm_class, mechanism_class
    assert all(algorithm_class(n).blas_free for n in ("abc", "gabc", "pso", "aco", "pabc"))
    assert not any(algorithm_class(n).blas_free for n in ("lm", "nr", "dls", "gabc+lm", "pso+lm", "scipy:differential_evolution"))
    assert mechanism_class("3-rps").blas_free_fitness and not mechanism_class("urdf").blas_free_fitness


def _nudged_starts(monkeypatch):
    """Every exact solver's start points moved by one ulp: a stand-in for another BLAS kernel."""
    import numpy as np

    from fkopt.algorithms import dls, lm, nr
    original = nr.start_points

    def nudged(*args, **kwargs):
        x = np.array(original(*args, **kwargs), dtype=float)
        return np.nextafter(x, np.inf)
    for module in (nr, lm, dls):
        monkeypatch.setattr(module, "start_points", nudged)


def test_one_ulp_in_the_exact_solvers_starts_passes_the_cross_platform_rules(monkeypatch, tmp_path):
    """Two reruns on this machine, the second with every exact solver's starts one ulp away: the
    bytes differ in the exact solvers' rows, and the "blas" rules (what --tolerant uses) pass."""
    from fkopt.run.compare import compare_folders
    from fkopt.run.pipeline import from_dict, rerun_files
    from fkopt.reproduce.check import rules_for
    exp = Store(RESULTS).get("chang2024", "baselines")
    config = from_dict(dict(exp.config), "chang2024/baselines")
    plain, nudged = tmp_path / "plain", tmp_path / "nudged"
    for folder in (plain, nudged):
        folder.mkdir()
    rerun_files(config, plain)
    _nudged_starts(monkeypatch)
    rerun_files(config, nudged)
    import pandas as pd
    a, b = (pd.read_csv(f / "runs.csv", dtype=str, keep_default_na=False) for f in (plain, nudged))
    moved = set(a["algorithm"][(a != b).any(axis=1)])
    assert moved and moved <= {"lm", "nr", "pso+lm"}, moved       # the nudge moved only exact solvers
    assert compare_folders("chang2024/baselines", plain, nudged, True)            # bytes differ
    assert compare_folders("chang2024/baselines", plain, nudged, rules_for(exp, "blas")) == []
    assert compare_folders("chang2024/baselines", plain, nudged, rules_for(exp, "any")) == []


@pytest.mark.parametrize("tier", ["exact", "blas", "any"])
def test_edits_of_path_dependent_rows_and_of_runs_are_caught_in_every_tier(tmp_path, tier):
    """An LM row's mean evaluations +2 %, a run's x moved by 5 degrees, a deleted claims.csv:
    caught whatever the platform (digests re-signed, so only the rules can tell)."""
    import pandas as pd
    dst = tmp_path / "results" / "chang2024"
    shutil.copytree(RESULTS / "chang2024" / "baselines", dst / "baselines")
    # an experiment the paper's claims are judged on: the tree has verdicts of chang2024, so a claims.csv
    shutil.copytree(RESULTS / "chang2024" / "tab1_fig7", dst / "tab1_fig7")
    folder = dst / "baselines"
    summary = pd.read_csv(folder / "summary.csv")
    row = int(summary.index[summary["algorithm"] == "lm"][0])
    _edit_csv(folder, "summary.csv", row, "mean_evaluations", lambda v: v * 1.02)
    runs = pd.read_csv(folder / "runs.csv")
    run = int(runs.index[runs["algorithm"] == "abc"][2])
    _edit_csv(folder, "runs.csv", run, "x_alpha", lambda v: v + 5)
    _resign(folder)
    (tmp_path / "results" / "REPORT.md").write_text("a tree written by fkopt reproduce\n")
    bad = check_experiment(Store(tmp_path / "results").get("chang2024", "baselines"), tier=tier)
    named = {(m.file, m.column) for m in bad}
    assert ("summary.csv", "mean_evaluations") in named
    assert ("runs.csv", "final_fitness") in named          # fitness(x) of the moved x is not the stored one
    assert ("claims.csv", "file") in named                  # the paper's claims.csv was not copied
    assert any("every platform" in m.rule for m in bad)


def test_rank_rules_see_a_real_shift_and_forgive_noise():
    """The distribution rule: a shifted path count fails, a reshuffle of the same values passes."""
    import numpy as np
    import pandas as pd

    from fkopt.run.compare import Rules, compare_runs
    rng = np.random.default_rng(1)
    n = 60
    base = pd.DataFrame({"case": "c", "algorithm": "lm", "run": np.arange(n), "final_fitness": 1e-25,
                         "evaluations": rng.integers(10, 30, n), "x_a": 1.0, "x_b": 2.0})
    rules = Rules("any")
    same = base.copy()
    same["evaluations"] = rng.permutation(base["evaluations"].to_numpy())
    assert compare_runs("e", "runs.csv", base.astype(str), same.astype(str), rules) == []
    shifted = base.copy()
    shifted["evaluations"] = base["evaluations"] + 8
    bad = compare_runs("e", "runs.csv", base.astype(str), shifted.astype(str), rules)
    assert [m.column for m in bad] == ["evaluations"] and "Holm" in bad[0].rule
    other = base.copy()
    other.loc[: n // 2, "x_a"] = -1.0                      # half the runs on another solution
    bad = compare_runs("e", "runs.csv", base.astype(str), other.astype(str), rules)
    assert [m.column for m in bad] == ["solutions"]


def test_a_study_run_moved_is_caught_by_its_recomputed_fitness(tmp_path):
    from fkopt.reproduce.check import recomputed_fitness
    from fkopt.run.pipeline import from_dict
    folder = _copy(tmp_path, "studies", "3rps_slice")
    exp = Store(folder.parents[1]).get("studies", "3rps_slice")
    config = from_dict(dict(exp.config), "studies/3rps_slice")
    assert recomputed_fitness(exp, config) == []
    _edit_csv(folder, "runs.csv", 7, "x_z", lambda v: v + 0.5)
    bad = recomputed_fitness(Store(folder.parents[1]).get("studies", "3rps_slice"), config)
    assert [(m.file, m.column) for m in bad] == [("runs.csv", "final_fitness")] and "pose" in bad[0].row


def test_check_cli_tolerant_forces_the_cross_platform_rules(tmp_path, cli):
    folder = _copy(tmp_path)
    code, out, err = cli("check", folder, "--tolerant")
    assert code == 0, err
    assert "ok   mao2017/tab6 (blas rules)" in out
    code, _, err = cli("check", folder, "--tier", "fuzzy")
    assert code == 2 and "--tier: 'fuzzy' unknown; allowed: auto, exact, blas, any" in err


def test_changes_say_what_a_regeneration_moved(tmp_path):
    from fkopt.reproduce.changes import describe, snapshot
    folder = _copy(tmp_path)
    shutil.copy(RESULTS / "mao2017" / "claims.csv", folder.parent / "claims.csv")
    before = snapshot(tmp_path / "results")
    assert "Unchanged (every deterministic file byte-identical): mao2017/tab6." in describe(before, tmp_path / "results")
    _edit_csv(folder, "summary.csv", 0, "mean_evaluations", lambda v: v + 20)
    import pandas as pd
    claims = pd.read_csv(folder.parent / "claims.csv", keep_default_na=False)
    first = claims.loc[0, "verdict"]
    claims.loc[0, "verdict"] = "not held" if first != "not held" else "held"
    claims.loc[1, "condition"] = "a reworded condition"    # keyed by id: a rewording is no move
    claims.to_csv(folder.parent / "claims.csv", index=False)
    text = describe(before, tmp_path / "results")
    assert "## mao2017/tab6" in text and "`summary.csv`" in text and "mean_evaluations" in text and "→" in text
    assert "## Verdicts that changed" in text and f"mao2017: {claims.loc[0, 'id']} (" in text
    assert f"{claims.loc[1, 'id']} (" not in text


def test_an_edited_timing_verdict_is_caught_on_any_platform(tmp_path):
    """Stored timing verdicts must be those of the stored timed runs (check measures no time)."""
    import pandas as pd

    from fkopt.reproduce.check import verdict_files
    shutil.copytree(RESULTS / "mao2017", tmp_path / "results" / "mao2017")
    exp = Store(tmp_path / "results").get("mao2017", "tab6")
    assert verdict_files(exp) == []
    file = tmp_path / "results" / "mao2017" / "timing_claims.csv"
    df = pd.read_csv(file, keep_default_na=False)
    df.loc[0, "verdict"] = "not held" if df.loc[0, "verdict"] != "not held" else "held"
    df.to_csv(file, index=False)
    bad = verdict_files(Store(tmp_path / "results").get("mao2017", "tab6"))
    assert [(m.file, m.column) for m in bad] == [("timing_claims.csv", "verdict")]
    assert "every platform" in bad[0].rule


def test_report_says_what_moved_since_a_recorded_snapshot(tmp_path, cli):
    """make bench-suite: fkopt report --snapshot-to before the rerun, --changes-since after."""
    folder = _copy(tmp_path)
    snap = tmp_path / "before.json"
    code, _, err = cli("report", tmp_path / "results", "--snapshot-to", snap)
    assert code == 0 and snap.is_file() and not (tmp_path / "results" / "REPORT.md").exists(), err
    _edit_csv(folder, "summary.csv", 0, "mean_evaluations", lambda v: v + 20)
    code, _, err = cli("report", tmp_path / "results", "--changes-since", snap)
    assert code == 0, err
    text = (tmp_path / "results" / "CHANGES.md").read_text()
    assert "## mao2017/tab6" in text and "mean_evaluations" in text
    snap.write_text('{"files": []}')
    code, _, err = cli("report", tmp_path / "results", "--changes-since", snap)
    assert code == 2 and "not a results snapshot" in err and len(err.strip().splitlines()) == 1
