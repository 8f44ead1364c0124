"""An experiment folder as IOH functions for ``fkopt export`` (``Kind.ioh_functions``): one
function named ``<paper>_<name>``, one instance per case, one algorithm per algorithm label, its
runs from ``trace.csv.gz`` (:mod:`fkopt.run.trace`) and ``runs.csv``; written by
:func:`fkopt.run.iohformat.write_function` (the layout: :mod:`fkopt.tools.export`)."""
from __future__ import annotations

from pathlib import Path

from fkopt.errors import FkoptError
from fkopt.run.iohformat import Function, stored_runs, trace_runs
from fkopt.run.trace import FILE, read_trace

#: The runs.csv columns the export reads (and the solution's ``x_<unknown>``, where kept).
RUN_COLUMNS = ("case", "algorithm", "run", "final_fitness")


def experiment_functions(folder: Path, meta: dict) -> list[Function]:
    """An experiment folder as one function (every field the export uses checked)."""
    path, config = folder / "meta.json", meta["config"]
    bounds = (meta.get("mechanism") or {}).get("bounds") if isinstance(meta.get("mechanism"), dict) else None
    if not isinstance(bounds, dict) or not bounds:
        raise FkoptError(f"{path}: no 'mechanism' with 'bounds' (the unknowns, the IOH dimension); "
                         "not a meta.json that fkopt wrote")
    if not isinstance(config.get("name"), str) or not isinstance(config.get("algorithms"), list):
        raise FkoptError(f"{path}: 'config' lacks 'name' or the 'algorithms' list")
    if not (folder / FILE).is_file():
        raise FkoptError(f"{folder}: no {FILE} (results written before fkopt kept run traces); "
                         "rerun the experiment to export it")
    trace = read_trace(folder)
    runs = stored_runs(folder, RUN_COLUMNS, ("case", "algorithm"))
    keys = ["case", "algorithm", "run"]
    groups = trace_runs(folder, trace, runs, keys, lambda k: f"run {k[2]} of algorithm '{k[1]}', case '{k[0]}'")
    names = list(bounds)
    cases = list(dict.fromkeys(runs["case"]))
    fn = Function(f"{config.get('paper') or 'experiments'}_{config['name']}", len(names), cases,
                  [{"variables": " ".join(names)}, {"source": str(folder)}])
    for label in dict.fromkeys(runs["algorithm"]):
        spec = next((a for a in config["algorithms"]
                     if isinstance(a, dict) and (a.get("label") or a.get("name")) == label), {})
        info = {"name": spec.get("name", label), "params": spec.get("params", {})}
        runs_a = runs[runs["algorithm"] == label]
        out = []
        for inst, case in enumerate(cases, start=1):
            for _, row in runs_a[runs_a["case"] == case].sort_values("run").iterrows():
                rows = groups[(case, label, row["run"])]
                out.append((inst, rows["evaluations"].to_numpy(), rows["best_fitness"].to_numpy(),
                            [float(row[f"x_{n}"]) for n in names if f"x_{n}" in row]))
        fn.algorithms[label] = (info, out)
    return [fn]
