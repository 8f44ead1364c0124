"""The outputs of every kind (each registered Kind's list of function objects; fkopt.run.writers writes
them): one writer, roles drive fkopt check."""
import json
from pathlib import Path

import pandas as pd
import pytest

import dataclasses

from fkopt.run import compare
from fkopt.run import writers as outputs
from fkopt.run.kinds import KINDS

ROOT = Path(__file__).resolve().parents[1]


def test_every_kind_lists_its_makers_as_function_objects():
    assert set(KINDS) == {"experiment", "study", "assembly", "suite"}
    for name, kind in KINDS.items():
        assert kind.outputs, name
        for out in kind.outputs:
            assert out.role in (outputs.TABLE, outputs.CURVES, outputs.TIMING, outputs.FIGURE), out
            assert callable(out.make) and not isinstance(out.make, str), out
        assert callable(kind.meta)


def test_compare_takes_its_file_sets_from_the_roles():
    timing = compare.timing_files()
    assert set(timing) == {o.file for k in KINDS.values() for o in k.outputs
                           if o.role == outputs.TIMING} | {"env.json"}
    assert "timing.csv" in timing and "env.json" in timing
    assert "summary.csv" not in timing
    # what a row of a file is (stats, runs, path steps) is the registry's too, one meaning per name
    rows: dict[str, set] = {}
    for k in KINDS.values():
        for o in k.outputs:
            assert o.rows in (outputs.STATS, outputs.RUNS, outputs.STEPS), o
            if o.role in (outputs.TABLE, outputs.CURVES):
                rows.setdefault(o.file, set()).add(o.rows)
    assert all(len(r) == 1 for r in rows.values()), rows
    assert set(compare.run_files()) == {f for f, r in rows.items() if r == {outputs.RUNS}} >= {"runs.csv"}
    assert set(compare.path_rows()) == {f for f, r in rows.items() if r == {outputs.STEPS}} >= {"trace.csv.gz"}


def _stored_folders():
    return sorted(p.parent for p in (ROOT / "results").glob("*/*/meta.json"))


@pytest.mark.parametrize("folder", _stored_folders(), ids=lambda p: f"{p.parent.name}/{p.name}")
def test_every_stored_file_is_a_registered_output(folder):
    meta = json.loads((folder / "meta.json").read_text())
    kind = meta.get("kind", "experiment")
    outs = outputs.outputs_of(kind)
    files = {o.file for o in outs if o.role != outputs.FIGURE}
    pages = {o.file for o in outs if o.role == outputs.FIGURE and "." in o.file}   # e.g. a suite's index.html
    for path in folder.iterdir():
        # a suite's index.html links pages of its own (arms.html, rankings.html: kinbench.pages)
        if path.suffix in (".png", ".pdf") or path.name in {outputs.META_FILE, outputs.ENV_FILE} | pages \
                or (kind == "suite" and path.suffix == ".html"):
            continue
        assert path.name in files, f"{folder.name}/{path.name} is not an output of kind {kind!r}"
    for name in meta["files"]:          # every recorded digest is of a deterministic output
        role = next(o.role for o in outs if o.file == name)
        assert role in (outputs.TABLE, outputs.CURVES), name


def test_a_new_output_is_one_line(tmp_path, monkeypatch):
    """A new table added to a kind's outputs is written, digested in meta.json and compared by check."""
    from fkopt.kinds.experiment.runner import run_experiment
    from fkopt.kinds.experiment.config import experiment_from_dict

    def extra_table(er):
        return pd.DataFrame({"case": [r.case.label for r in er.own.solves],
                             "best": [float(r.result.fitness.min()) for r in er.own.solves]})
    experiment = KINDS["experiment"]
    monkeypatch.setitem(KINDS, "experiment", dataclasses.replace(
        experiment, outputs=experiment.outputs + (outputs.Output("extra.csv", extra_table, outputs.TABLE),)))
    cfg = experiment_from_dict({"name": "x", "mechanism": {"name": "3-rps"},
                                "cases": [{"pose": {"alpha": 5, "beta": 3, "z": 600}}],
                                "algorithms": [{"name": "gabc"}], "iterations": 20, "runs": 2}, "t")
    er = run_experiment(cfg, timing=False)
    written = outputs.write_outputs("experiment", er, tmp_path, figures=False, timing=False)
    assert "extra.csv" in written and "timing.csv" not in written
    meta = json.loads((tmp_path / "meta.json").read_text())
    assert meta["files"]["extra.csv"] == outputs.sha256(tmp_path / "extra.csv")
    assert "extra.csv" in compare.deterministic_files(tmp_path)
