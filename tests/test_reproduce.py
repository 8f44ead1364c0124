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
