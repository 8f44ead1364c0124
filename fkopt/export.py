"""Export stored results for other tools: ``fkopt export RESULTS --format ioh --out DIR``.

``ioh``: the files that the ``ioh`` package's ``ioh.logger.Analyzer`` writes (IOHexperimenter;
what IOHanalyzer and iohinspector load), built from each experiment folder's ``meta.json``,
``runs.csv`` and ``trace.csv.gz`` (:mod:`fkopt.experiment.traces`) -- no rerun. Mapping:

* one **algorithm** folder per algorithm label: ``DIR/<label>/``;
* one **function** per experiment: ``function_id`` numbers the exported experiments (sorted by
  paper/name, from 1), ``function_name`` is ``<paper>_<name>``;
* one **instance** per case (case index + 1; the labels are the experiment attribute
  ``instances``), the **dimension** is the number of unknowns, each **run** one IOH run (per
  instance in the order of fkopt's run ids);
* ``DIR/<label>/IOHprofiler_f<id>_<name>.json`` is the index, with the keys and layout of the
  Analyzer's (``version``, ``suite``, ``function_id``, ``function_name``, ``maximization``,
  ``algorithm``, ``experiment_attributes``, ``attributes``, ``scenarios`` with per run
  ``instance``, ``evals``, ``best``), and ``DIR/<label>/data_f<id>_<name>/IOHprofiler_f<id>_DIM<dim>.dat``
  the data: a header line ``evaluations raw_y`` opens each run, then one line per improvement of
  the best-so-far fitness at its exact evaluation number -- the first line is evaluation 1, as
  IOH readers split runs there -- and a last line at the run's final evaluation count (its
  best-so-far fitness) when the last improvement came earlier.

``version`` is the ``ioh`` release whose Analyzer output this layout was compared with
(:data:`IOH_VERSION`); fkopt's version is in ``algorithm.info`` and in the manifest
``DIR/fkopt-export.txt``. The manifest (which folders were exported, and the mark that lets a
later export replace ``DIR``) is not a ``.json`` or ``.info`` file, so IOH readers, which load
every ``**/*.json``, never mistake it for an index. The folder is written atomically, after every
input file has been read and checked, and only over a folder that ``fkopt export`` wrote before.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import FkoptError
from .iohformat import ATTRIBUTES, IOH_VERSION, read_ioh  # noqa: F401  (read_ioh: the reader, here as before)

FORMATS = ("ioh",)
MARKER = "fkopt-export.txt"
#: Marks of folders written by earlier fkopt releases (replaced like MARKER's).
OLD_MARKERS = ("fkopt-export.json",)
RUN_COLUMNS = ("case", "algorithm", "run", "final_fitness")


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
    if out.is_dir() and any(out.iterdir()) and not any((out / m).is_file() for m in (MARKER,) + OLD_MARKERS):
        raise FkoptError(f"--out {out}: folder exists and was not written by fkopt export; choose a new folder")
    return out


def _safe(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "-", str(text)).strip("-") or "x"


def _load(folder: Path):
    """(meta, trace, runs) of an experiment folder, every field the export uses checked; None
    for studies and assembly searches (no per-run traces)."""
    path = folder / "meta.json"
    try:
        meta = json.loads(path.read_text())
    except (OSError, ValueError) as err:
        raise FkoptError(f"{path}: cannot read ({err})") from None
    config = meta.get("config") if isinstance(meta, dict) else None
    if not isinstance(config, dict):
        raise FkoptError(f"{path}: no 'config' object (not a meta.json that fkopt wrote)")
    if config.get("kind") in ("study", "assembly"):
        return None
    bounds = (meta.get("mechanism") or {}).get("bounds") if isinstance(meta.get("mechanism"), dict) else None
    if not isinstance(bounds, dict) or not bounds:
        raise FkoptError(f"{path}: no 'mechanism' with 'bounds' (the unknowns, the IOH dimension); "
                         "not a meta.json that fkopt wrote")
    if not isinstance(config.get("name"), str) or not isinstance(config.get("algorithms"), list):
        raise FkoptError(f"{path}: 'config' lacks 'name' or the 'algorithms' list")
    from .experiment.traces import FILE, read_trace
    if not (folder / FILE).is_file():
        raise FkoptError(f"{folder}: no {FILE} (results written before fkopt kept run traces); "
                         "rerun the experiment to export it")
    trace = read_trace(folder)
    path = folder / "runs.csv"
    try:
        runs = pd.read_csv(path, dtype={"case": str, "algorithm": str})
    except (OSError, ValueError, pd.errors.ParserError, UnicodeDecodeError) as err:
        raise FkoptError(f"{path}: cannot read ({str(err).strip().splitlines()[0] if str(err).strip() else err})") from None
    missing = [c for c in RUN_COLUMNS if c not in runs.columns]
    if missing:
        raise FkoptError(f"{path}: missing column(s) {', '.join(missing)}")
    runs["run"] = pd.to_numeric(runs["run"], errors="coerce")
    if runs["run"].isna().any():
        raise FkoptError(f"{path}: column run: run ids must be integers")
    runs["run"] = runs["run"].astype(np.int64)
    keys = ["case", "algorithm", "run"]
    grouped = trace.groupby(keys, sort=False, observed=True)["evaluations"]
    first = grouped.first()
    have = runs.set_index(keys).index
    absent = ~have.isin(first.index)
    if absent.any():
        c, a, r = have[absent][0]
        raise FkoptError(f"{folder / FILE}: no rows for run {r} of algorithm '{a}', case '{c}' "
                         f"({int(absent.sum())} of the {len(runs)} runs of runs.csv have none)")
    late = first[first != 1]
    if len(late):
        (c, a, r), e = late.index[0], int(late.iloc[0])
        raise FkoptError(f"{folder / FILE}: run {r} of algorithm '{a}', case '{c}' starts at evaluation {e}, "
                         "not 1 (a trace written before fkopt counted evaluations exactly); rerun the experiment")
    rising = grouped.diff().fillna(1) > 0
    if not rising.all():
        i = int(np.flatnonzero(~rising.to_numpy())[0])
        c, a, r = (trace[k].iloc[i] for k in keys)
        raise FkoptError(f"{folder / FILE}: row {i + 1} (run {r} of algorithm '{a}', case '{c}'): evaluations "
                         "do not increase within the run")
    return meta, trace, runs


def _index(fid: int, fname: str, label: str, spec: dict, cases: list, names: list, folder: Path,
           data_rel: str, dim: int, runs: list) -> dict:
    from . import __version__
    return {
        "version": IOH_VERSION, "suite": "fkopt", "function_id": fid, "function_name": fname,
        "maximization": False,
        "algorithm": {"name": label, "info": json.dumps({"name": spec.get("name", label),
                                                         "params": spec.get("params", {}),
                                                         "fkopt": __version__})},
        "experiment_attributes": [{"instances": "; ".join(f"{i}={c}" for i, c in enumerate(cases, start=1))},
                                  {"variables": " ".join(names)},
                                  {"source": str(folder)}],
        "attributes": ATTRIBUTES,
        "scenarios": [{"dimension": dim, "path": data_rel, "runs": runs}],
    }


def ioh_export(results: Path, out: Path) -> list[Path]:
    """Write the IOHprofiler files of every experiment under ``results`` into ``out``; returns
    the index files written."""
    from . import __version__
    from .files import write_atomically
    folders = experiment_folders(results)
    out = check_out(out, results)
    loaded = [(f, data) for f in folders if (data := _load(f)) is not None]
    if not loaded:
        raise FkoptError(f"{results}: only studies/assembly results, which have no per-run traces to export")
    from .files import output_folder   # the shared checks (a folder, writable), once the inputs are good
    output_folder(out)

    def write(tmp: Path) -> None:
        for fid, (folder, (meta, trace, runs)) in enumerate(loaded, start=1):
            config = meta["config"]
            fname = _safe(f"{config.get('paper') or 'experiments'}_{config['name']}")
            names = list(meta["mechanism"]["bounds"])
            dim = len(names)
            cases = list(dict.fromkeys(runs["case"]))
            groups = dict(list(trace.groupby(["case", "algorithm", "run"], sort=False, observed=True)))
            for label in dict.fromkeys(runs["algorithm"]):
                algo_dir = tmp / _safe(label)
                data_rel = f"data_f{fid}_{fname}/IOHprofiler_f{fid}_DIM{dim}.dat"
                (algo_dir / data_rel).parent.mkdir(parents=True, exist_ok=True)
                lines, index_runs = [], []
                runs_a = runs[runs["algorithm"] == label]
                spec = next((a for a in config["algorithms"]
                             if isinstance(a, dict) and (a.get("label") or a.get("name")) == label), {})
                for inst, case in enumerate(cases, start=1):
                    for _, row in runs_a[runs_a["case"] == case].sort_values("run").iterrows():
                        rows = groups[(case, label, row["run"])]
                        e = rows["evaluations"].to_numpy()
                        y = rows["best_fitness"].to_numpy()
                        lines.append(" ".join(ATTRIBUTES))
                        lines += [f"{int(a)} {b:.10g}" for a, b in zip(e, y)]
                        final = float(y[-1])
                        x = [float(row[f"x_{n}"]) for n in names if f"x_{n}" in row]
                        index_runs.append({"instance": inst, "evals": int(e[-1]),
                                           "best": {"evals": int(e[np.argmax(y <= final)]), "y": final, "x": x}})
                (algo_dir / data_rel).write_text("\n".join(lines) + "\n")
                index = _index(fid, fname, label, spec, cases, names, folder, data_rel, dim, index_runs)
                (algo_dir / f"IOHprofiler_f{fid}_{fname}.json").write_text(json.dumps(index, indent=1) + "\n")
        (tmp / MARKER).write_text("fkopt export (IOHprofiler format; this file is the export's mark, "
                                  "not data)\n" + f"format: ioh\nfkopt: {__version__}\nioh layout: {IOH_VERSION}\n"
                                  + "experiments:\n" + "".join(f"  {f}\n" for f, _ in loaded))

    write_atomically(out, write)
    return sorted(out.glob("*/IOHprofiler_f*.json"))
