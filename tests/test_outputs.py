"""The output registry (fkopt.outputs): one table of every file, one writer, roles drive fkopt check."""
import json
from pathlib import Path

import pandas as pd
import pytest

from fkopt import compare, outputs

ROOT = Path(__file__).resolve().parents[1]


def test_every_maker_resolves():
    for kind, outs in outputs.OUTPUTS.items():
        assert outs, kind
        for out in outs:
            assert out.role in (outputs.TABLE, outputs.CURVES, outputs.TIMING, outputs.FIGURE), out
            assert callable(outputs._load(out.make)), out.make
        assert callable(outputs._load(outputs.META[kind]))


def test_compare_takes_its_file_sets_from_the_roles():
    assert set(compare.TIMING_FILES) == {o.file for outs in outputs.OUTPUTS.values() for o in outs
                                         if o.role == outputs.TIMING} | {"env.json"}
    assert "timing.csv" in compare.TIMING_FILES and "env.json" in compare.TIMING_FILES
    assert "summary.csv" not in compare.TIMING_FILES
    # what a row of a file is (stats, runs, path steps) is the registry's too, one meaning per name
    rows: dict[str, set] = {}
    for outs in outputs.OUTPUTS.values():
        for o in outs:
            assert o.rows in (outputs.STATS, outputs.RUNS, outputs.STEPS), o
            if o.role in (outputs.TABLE, outputs.CURVES):
                rows.setdefault(o.file, set()).add(o.rows)
    assert all(len(r) == 1 for r in rows.values()), rows
    assert set(compare.RUN_FILES) == {f for f, r in rows.items() if r == {outputs.RUNS}} >= {"runs.csv"}
    assert set(compare.PATH_ROWS) == {f for f, r in rows.items() if r == {outputs.STEPS}} >= {"trace.csv.gz"}


def _stored_folders():
    return sorted(p.parent for p in (ROOT / "results").glob("*/*/meta.json"))


@pytest.mark.parametrize("folder", _stored_folders(), ids=lambda p: f"{p.parent.name}/{p.name}")
def test_every_stored_file_is_a_registered_output(folder):
    meta = json.loads((folder / "meta.json").read_text())
    kind = meta.get("kind", "experiment")
    outs = outputs.OUTPUTS[kind]
    files = {o.file for o in outs if o.role != outputs.FIGURE}
    pages = {o.file for o in outs if o.role == outputs.FIGURE and "." in o.file}   # e.g. a suite's index.html
    for path in folder.iterdir():
        if path.suffix in (".png", ".pdf") or path.name in {outputs.META_FILE, outputs.ENV_FILE} | pages:
            continue
        assert path.name in files, f"{folder.name}/{path.name} is not in fkopt.outputs.OUTPUTS[{kind!r}]"
    for name in meta["files"]:          # every recorded digest is of a deterministic output
        role = next(o.role for o in outs if o.file == name)
        assert role in (outputs.TABLE, outputs.CURVES), name


def test_a_new_output_is_one_line(tmp_path, monkeypatch):
    """A new table registered in OUTPUTS is written, digested in meta.json and compared by check."""
    import sys
    import types
    from fkopt.experiment.runner import run_experiment
    from fkopt.experiment.config import experiment_from_dict

    mod = types.ModuleType("fkopt_test_extra")
    mod.extra_table = lambda er: pd.DataFrame({"case": [r.case.label for r in er.records],
                                               "best": [float(r.result.fitness.min()) for r in er.records]})
    monkeypatch.setitem(sys.modules, "fkopt_test_extra", mod)
    monkeypatch.setitem(outputs.OUTPUTS, "experiment",
                        outputs.OUTPUTS["experiment"] + (outputs.Output("extra.csv", "fkopt_test_extra:extra_table",
                                                                        outputs.TABLE),))
    cfg = experiment_from_dict({"name": "x", "mechanism": {"name": "3-rps"},
                                "cases": [{"pose": {"alpha": 5, "beta": 3, "z": 600}}],
                                "algorithms": [{"name": "gabc"}], "iterations": 20, "runs": 2}, "t")
    er = run_experiment(cfg, timing=False)
    written = outputs.write_outputs("experiment", er, tmp_path, figures=False, timing=False)
    assert "extra.csv" in written and "timing.csv" not in written
    meta = json.loads((tmp_path / "meta.json").read_text())
    assert meta["files"]["extra.csv"] == outputs.sha256(tmp_path / "extra.csv")
    assert "extra.csv" in compare.deterministic_files(tmp_path)
