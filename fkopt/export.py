"""Export stored results for other tools: ``fkopt export RESULTS --format ioh --out DIR``.

``ioh``: IOHprofiler's data format (what IOHexperimenter's ``Analyzer`` logger writes and
IOHanalyzer loads), built from each experiment folder's ``meta.json``, ``runs.csv`` and
``trace.csv.gz`` (:mod:`fkopt.experiment.traces`) -- no rerun. Mapping:

* one **algorithm** folder per algorithm label: ``DIR/<label>/``;
* one **function** per experiment: ``function_id`` numbers the exported experiments (sorted by
  paper/name, from 1), ``function_name`` is ``<paper>_<name>``;
* one **instance** per case (case index + 1; the label is in ``experiment_attributes``), the
  **dimension** is the number of unknowns, each **run** one IOH run;
* ``DIR/<label>/IOHprofiler_f<id>_<name>.json`` is the index (suite ``fkopt``, minimisation,
  per run its instance, evaluations used and best point), and
  ``DIR/<label>/data_f<id>_<name>/IOHprofiler_f<id>_DIM<dim>.dat`` the improvement-based
  trace: a header line ``evaluations raw_y`` opens each run, then one line per improvement of
  the best-so-far fitness, the last line being the run's final evaluation count (as IOH's
  ``.dat`` files must end when the target is not reached).

The evaluation counts have the resolution of the stored trace (end of the iteration in which
an improvement happened). The folder is written atomically, and only over a folder that
``fkopt export`` wrote before (it holds ``fkopt-export.json``).
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import FkoptError

FORMATS = ("ioh",)
MARKER = "fkopt-export.json"


def experiment_folders(results: Path) -> list[Path]:
    """Experiment folders under ``results``: the folder itself, or ``*/meta.json``, ``*/*/meta.json``."""
    results = Path(results)
    if not results.is_dir():
        raise FkoptError(f"{results}: not a results folder (no such directory)")
    if (results / "meta.json").is_file():
        return [results]
    found = sorted({p.parent for pat in ("*/meta.json", "*/*/meta.json") for p in results.glob(pat)})
    if not found:
        raise FkoptError(f"{results}: no experiment results (no meta.json in it or its subfolders)")
    return found


def check_out(out: Path, results: Path) -> Path:
    """Refuse an --out that would overwrite stored results or an unrelated folder."""
    out, res = Path(out).resolve(), Path(results).resolve()
    if out == res or res in out.parents or out in res.parents:
        raise FkoptError(f"--out {out}: must lie outside the results folder {res} (and not contain it)")
    if out.exists() and not out.is_dir():
        raise FkoptError(f"--out {out}: exists and is not a folder")
    if out.is_dir() and any(out.iterdir()) and not (out / MARKER).is_file():
        raise FkoptError(f"--out {out}: folder exists and was not written by fkopt export; choose a new folder")
    from .files import output_folder   # the shared checks: a folder, writable, nothing below a file
    output_folder(out)
    return out


def _safe(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "-", str(text)).strip("-") or "x"


def _load(folder: Path):
    try:
        meta = json.loads((folder / "meta.json").read_text())
    except (OSError, ValueError) as err:
        raise FkoptError(f"{folder / 'meta.json'}: cannot read ({err})") from None
    if meta.get("config", {}).get("kind") in ("study", "assembly"):
        return None
    from .experiment.traces import FILE, read_trace
    if not (folder / FILE).is_file():
        raise FkoptError(f"{folder}: no {FILE} (results written before fkopt kept run traces); "
                         "rerun the experiment to export it")
    return meta, read_trace(folder), pd.read_csv(folder / "runs.csv")


def ioh_export(results: Path, out: Path) -> list[Path]:
    """Write the IOHprofiler files of every experiment under ``results`` into ``out``."""
    from . import __version__
    from .files import write_atomically
    folders = experiment_folders(results)
    out = check_out(out, results)
    loaded = [(f, data) for f in folders if (data := _load(f)) is not None]
    if not loaded:
        raise FkoptError(f"{results}: only studies/assembly results, which have no per-run traces to export")

    def write(tmp: Path) -> None:
        for fid, (folder, (meta, trace, runs)) in enumerate(loaded, start=1):
            config = meta["config"]
            fname = _safe(f"{config.get('paper') or 'experiments'}_{config['name']}")
            names = list(meta["mechanism"]["bounds"])
            dim = len(names)
            cases = list(dict.fromkeys(runs["case"]))
            for label in dict.fromkeys(trace["algorithm"]):
                algo_dir = tmp / _safe(label)
                data_rel = f"data_f{fid}_{fname}/IOHprofiler_f{fid}_DIM{dim}.dat"
                (algo_dir / data_rel).parent.mkdir(parents=True, exist_ok=True)
                lines, index_runs = [], []
                tr_a, runs_a = trace[trace["algorithm"] == label], runs[runs["algorithm"] == label]
                spec = next((a for a in config["algorithms"] if (a.get("label") or a["name"]) == label), {})
                for inst, case in enumerate(cases, start=1):
                    for _, row in runs_a[runs_a["case"] == case].sort_values("run").iterrows():
                        rows = tr_a[(tr_a["case"] == case) & (tr_a["run"] == row["run"])]
                        lines.append("evaluations raw_y")
                        lines += [f"{int(e)} {y:.10g}" for e, y in zip(rows["evaluations"], rows["best_fitness"])]
                        final = float(rows["best_fitness"].iloc[-1])
                        first = int(rows["evaluations"][rows["best_fitness"] <= final].iloc[0])
                        x = [float(row[f"x_{n}"]) for n in names if f"x_{n}" in row]
                        index_runs.append({"instance": inst, "evals": int(rows["evaluations"].iloc[-1]),
                                           "best": {"evals": first, "y": final, "x": x},
                                           "run_id": int(row["run"])})
                (algo_dir / data_rel).write_text("\n".join(lines) + "\n")
                index = {
                    "version": f"fkopt {__version__}", "suite": "fkopt", "function_id": fid,
                    "function_name": fname, "maximization": False,
                    "algorithm": {"name": label, "info": json.dumps({"name": spec.get("name", label),
                                                                     "params": spec.get("params", {})})},
                    "experiment_attributes": [{"instances": ", ".join(f"{i}={c}" for i, c in
                                                                       enumerate(cases, start=1))},
                                              {"variables": ", ".join(names)},
                                              {"source": str(folder)}],
                    "scenarios": [{"dimension": dim, "path": data_rel, "runs": index_runs}],
                }
                (algo_dir / f"IOHprofiler_f{fid}_{fname}.json").write_text(json.dumps(index, indent=1) + "\n")
        (tmp / MARKER).write_text(json.dumps({"format": "ioh", "fkopt": __version__,
                                              "experiments": [str(f) for f, _ in loaded]}, indent=1) + "\n")

    write_atomically(out, write)
    return sorted(out.rglob("*.json"))


def read_ioh(folder: Path) -> dict:
    """Read an IOH export back: {(algorithm, function_name, instance): [runs as (evals, y) arrays]}
    and the index files -- what IOHanalyzer would see (used by the tests)."""
    out: dict = {}
    for index_file in sorted(Path(folder).glob("*/IOHprofiler_f*.json")):
        index = json.loads(index_file.read_text())
        for sc in index["scenarios"]:
            blocks, current = [], None
            for line in (index_file.parent / sc["path"]).read_text().splitlines():
                if line.startswith("evaluations"):
                    current = []
                    blocks.append(current)
                elif line.strip():
                    e, y = line.split()
                    current.append((int(e), float(y)))
            if len(blocks) != len(sc["runs"]):
                raise ValueError(f"{index_file}: {len(sc['runs'])} runs indexed, {len(blocks)} in the .dat")
            for run, block in zip(sc["runs"], blocks):
                key = (index["algorithm"]["name"], index["function_name"], run["instance"])
                out.setdefault(key, []).append((np.array(block, dtype=float), run))
    return out
