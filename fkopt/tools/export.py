"""Export stored results for other tools: ``fkopt export RESULTS --format ioh --out DIR``.

``ioh``: the files that the ``ioh`` package's ``ioh.logger.Analyzer`` writes (IOHexperimenter;
what IOHanalyzer and iohinspector load), built from each experiment or suite folder's
``meta.json``, ``runs.csv`` and ``trace.csv.gz`` (:mod:`fkopt.run.trace`,
:mod:`fkopt.kinbench.traces`) -- no rerun. Every folder becomes IOH *functions*
(:class:`Function`), which one writer (:func:`_write_function`) writes; mapping:

* one **algorithm** folder per algorithm label (an experiment's) or solver label (a suite's,
  outside solvers included): ``DIR/<label>/``;
* **functions**: an experiment is one, named ``<paper>_<name>``, with one **instance** per case
  (case index + 1); a suite is one per problem, named by the problem, with one instance per
  (set, pose) in the suite's set order, then pose order (from 1). The instance labels are the
  experiment attribute ``instances`` (``1=<case>``; ``1=<set>/<pose>``). ``function_id``
  numbers the functions from 1 over the exported folders (sorted by path) and, within a
  suite, its problems in the suite's order -- so a suite exported alone has function_id =
  problem order;
* the **dimension** is the number of unknowns, each **run** one IOH run (per instance in the
  order of the run ids);
* ``DIR/<label>/IOHprofiler_f<id>_<name>.json`` is the index, with the keys and layout of the
  Analyzer's (``version``, ``suite``, ``function_id``, ``function_name``, ``maximization``,
  ``algorithm``, ``experiment_attributes``, ``attributes``, ``scenarios`` with per run
  ``instance``, ``evals``, ``best``), and ``DIR/<label>/data_f<id>_<name>/IOHprofiler_f<id>_DIM<dim>.dat``
  the data: a header line ``evaluations raw_y`` opens each run, then one line per improvement of
  the best-so-far fitness at its exact evaluation number -- the first line is evaluation 1, as
  IOH readers split runs there -- and a last line at the run's final evaluation count (its
  best-so-far fitness) when the last improvement came earlier. A suite's run that had no
  fitness value yet writes ``inf`` in the ``.dat`` and a ``null`` best ``y`` in the index
  (strict JSON has no infinity).

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
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

import fkopt
from fkopt.errors import FkoptError
from fkopt.files import (csv_numbers, file_names, output_folder, parse_json, read_stored, read_stored_csv,
                         write_atomically)
from fkopt.kinbench.traces import COLUMNS, KEYS
from fkopt.run.trace import FILE, read_trace
from fkopt.tools.iohformat import ATTRIBUTES, IOH_VERSION, read_ioh  # noqa: F401  (read_ioh: the reader, here as before)

FORMATS = ("ioh",)
MARKER = "fkopt-export.txt"
#: Marks of folders written by earlier fkopt releases (replaced like MARKER's).
OLD_MARKERS = ("fkopt-export.json",)
RUN_COLUMNS = ("case", "algorithm", "run", "final_fitness")


def experiment_folders(results: Path) -> list[Path]:
    """Result folders (experiments, suites, ...) under ``results``: the folder itself, or
    ``*/meta.json``, ``*/*/meta.json``."""
    results = Path(results)
    if not results.is_dir():
        raise FkoptError(f"{results}: not a results folder (no such directory)")
    if (results / "meta.json").is_file():
        return [results]
    found = sorted({p.parent for pat in ("*/meta.json", "*/*/meta.json") for p in results.glob(pat)})
    if not found:
        raise FkoptError(f"{results}: no experiment or suite results (no meta.json in it or its subfolders)")
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


def algorithm_folders(labels) -> dict[str, str]:
    """The export's folder of each algorithm label, one per label (:func:`fkopt.files.file_names`):
    ``pso+lm`` and an outside solver ``pso-lm`` never share a folder (nor its index files)."""
    return file_names(labels, allowed="A-Za-z0-9_.-", sep="-")


@dataclass
class Function:
    """One IOH function of an exported folder: an experiment, or one problem of a suite."""

    name: str                        # function_name (made file-safe when written)
    dim: int
    instances: list[str]             # the label of instance i + 1
    attributes: list[dict]           # experiment attributes after ``instances``
    #: algorithm label -> (``algorithm.info`` content, runs: (instance, evaluations, best-so-far, x))
    algorithms: dict[str, tuple[dict, list]] = field(default_factory=dict)


def _meta(folder: Path) -> dict:
    path = folder / "meta.json"
    try:
        meta = parse_json(read_stored(folder, "meta.json"), str(path))
    except FkoptError as err:
        raise FkoptError(f"{path}: cannot read ({str(err).removeprefix(f'{path}: ')})") from None
    if not isinstance(meta, dict) or not isinstance(meta.get("config"), dict):
        raise FkoptError(f"{path}: no 'config' object (not a meta.json that fkopt wrote)")
    return meta


def _runs_csv(folder: Path, columns, labels) -> pd.DataFrame:
    path = folder / "runs.csv"
    try:
        runs = read_stored_csv(folder, "runs.csv", dtype=dict.fromkeys(labels, str))
    except (OSError, ValueError, pd.errors.ParserError, UnicodeDecodeError) as err:
        raise FkoptError(f"{path}: cannot read ({str(err).strip().splitlines()[0] if str(err).strip() else err})") from None
    missing = [c for c in columns if c not in runs.columns]
    if missing:
        raise FkoptError(f"{path}: missing column(s) {', '.join(missing)}")
    for col in ("run", "pose", "dim"):
        if col in columns:
            num = pd.Series(csv_numbers(runs[col]), index=runs.index)     # never raises; range-checked here
            if num.isna().any() or (num != np.floor(num)).any() or (num.abs() > 2 ** 53).any():
                raise FkoptError(f"{path}: column {col}: {col} ids must be integers")
            runs[col] = num.astype(np.int64)
    return runs


def _checked_groups(folder: Path, trace: pd.DataFrame, runs: pd.DataFrame, keys: list[str], what) -> dict:
    """The trace rows of every run of ``runs`` (keyed by ``keys``), checked: every run has rows,
    starting at evaluation 1, with increasing evaluations. ``what(key)`` names a run in errors."""
    for k in keys:                                       # labels compare as text, ids as integers
        if trace[k].dtype.name == "category":
            trace[k] = trace[k].astype(str)
    grouped = trace.groupby(keys, sort=False, observed=True)["evaluations"]
    first = grouped.first()
    have = runs.set_index(keys).index
    absent = ~have.isin(first.index)
    if absent.any():
        raise FkoptError(f"{folder / FILE}: no rows for {what(have[absent][0])} "
                         f"({int(absent.sum())} of the {len(runs)} runs of runs.csv have none)")
    late = first[first != 1]
    if len(late):
        raise FkoptError(f"{folder / FILE}: {what(late.index[0])} starts at evaluation {int(late.iloc[0])}, "
                         "not 1 (a trace written before fkopt counted evaluations exactly); rerun it")
    rising = grouped.diff().fillna(1) > 0
    if not rising.all():
        i = int(np.flatnonzero(~rising.to_numpy())[0])
        raise FkoptError(f"{folder / FILE}: row {i + 1} ({what(tuple(trace[k].iloc[i] for k in keys))}): "
                         "evaluations do not increase within the run")
    return dict(list(trace.groupby(keys, sort=False, observed=True)))


def _experiment(folder: Path, meta: dict) -> list[Function]:
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
    runs = _runs_csv(folder, RUN_COLUMNS, ("case", "algorithm"))
    keys = ["case", "algorithm", "run"]
    groups = _checked_groups(folder, trace, runs, keys, lambda k: f"run {k[2]} of algorithm '{k[1]}', case '{k[0]}'")
    names = list(bounds)
    cases = list(dict.fromkeys(runs["case"]))
    fn = Function(f"{config.get('paper') or 'experiments'}_{config['name']}", len(names), cases,
                  [{"variables": " ".join(names)}, {"source": str(folder)}])
    for label in dict.fromkeys(runs["algorithm"]):
        spec = next((a for a in config["algorithms"]
                     if isinstance(a, dict) and (a.get("label") or a.get("name")) == label), {})
        info = {"name": spec.get("name", label), "params": spec.get("params", {}), "fkopt": fkopt.__version__}
        runs_a = runs[runs["algorithm"] == label]
        out = []
        for inst, case in enumerate(cases, start=1):
            for _, row in runs_a[runs_a["case"] == case].sort_values("run").iterrows():
                rows = groups[(case, label, row["run"])]
                out.append((inst, rows["evaluations"].to_numpy(), rows["best_fitness"].to_numpy(),
                            [float(row[f"x_{n}"]) for n in names if f"x_{n}" in row]))
        fn.algorithms[label] = (info, out)
    return [fn]


def _suite(folder: Path, meta: dict) -> list[Function]:
    """A suite folder (:mod:`fkopt.kinbench`) as one function per problem, in the suite's order:
    one instance per (set, pose) in set-then-pose order, one algorithm per solver."""
    path, config = folder / "meta.json", meta["config"]
    problems, sets = config.get("problems"), config.get("sets")
    if not (isinstance(problems, list) and all(isinstance(p, dict) and isinstance(p.get("name"), str) for p in problems)
            and isinstance(sets, list) and isinstance(config.get("name"), str)):
        raise FkoptError(f"{path}: 'config' lacks the suite's 'name', 'problems' or 'sets'")
    if not (folder / FILE).is_file():
        raise FkoptError(f"{folder}: no {FILE} (suite results written before fkopt kept run traces); "
                         "rerun the suite to export it")
    trace = read_trace(folder, columns=COLUMNS)
    runs = _runs_csv(folder, KEYS + ["dim", "track"], ("problem", "set", "solver", "track"))
    groups = _checked_groups(folder, trace, runs, KEYS, lambda k: f"run {k[4]} of solver '{k[3]}', problem "
                             f"'{k[0]}', set '{k[1]}', pose {k[2]}")
    specs = {(s.get("label") or s.get("name")): s for s in config.get("solvers") or [] if isinstance(s, dict)}
    outside = {o.get("solver"): o for o in config.get("outside") or [] if isinstance(o, dict)}
    set_order = {s: j for j, s in enumerate(sets)}
    out = []
    for problem in problems:
        rp = runs[runs["problem"] == problem["name"]]
        if rp.empty:
            continue
        inst = sorted(set(zip(rp["set"], rp["pose"])), key=lambda sp: (set_order.get(sp[0], len(sets)), sp[0], sp[1]))
        number = {sp: i for i, sp in enumerate(inst, start=1)}
        fn = Function(problem["name"], int(rp["dim"].iloc[0]), [f"{s}/{p}" for s, p in inst],
                      [{"benchmark": f"{config.get('paper') or 'kinbench'}/{config['name']}"},
                       {"problem_class": str(problem.get("problem_class", ""))}, {"source": str(folder)}])
        for label in dict.fromkeys(rp["solver"]):
            rs = rp[rp["solver"] == label]
            spec = specs.get(label)
            info = ({"name": spec.get("name", label), "params": spec.get("params", {})} if spec is not None else
                    {"name": label, "outside": outside.get(label, {}).get("file") or outside.get(label, {}).get("ioh")})
            info.update(track=str(rs["track"].iloc[0]), fkopt=fkopt.__version__)
            order = sorted(zip(rs["set"], rs["pose"], rs["run"]), key=lambda k: (number[k[:2]], k[2]))
            runs_l = []
            for s, p, r in order:
                rows = groups[(problem["name"], s, p, label, r)]
                runs_l.append((number[(s, p)], rows["evaluations"].to_numpy(), rows["best_fitness"].to_numpy(), []))
            fn.algorithms[label] = (info, runs_l)
        out.append(fn)
    return out


def _load(folder: Path) -> list[Function] | None:
    """The IOH functions of a results folder: an experiment's one, a suite's one per problem;
    None for studies and assembly searches (no per-run traces)."""
    meta = _meta(folder)
    if meta["config"].get("kind") in ("study", "assembly"):
        return None
    if meta.get("kind") == "suite" or meta["config"].get("kind") == "suite":
        return _suite(folder, meta)
    return _experiment(folder, meta)


def _finite(y: float):
    """A best value for the JSON index: a number, or null when none was found (strict JSON has
    no infinity)."""
    return y if np.isfinite(y) else None


def _index(fid: int, fname: str, label: str, info: dict, fn: Function, data_rel: str, runs: list) -> dict:
    return {
        "version": IOH_VERSION, "suite": "fkopt", "function_id": fid, "function_name": fname,
        "maximization": False,
        "algorithm": {"name": label, "info": json.dumps(info)},
        "experiment_attributes": [{"instances": "; ".join(f"{i}={c}" for i, c in enumerate(fn.instances, start=1))},
                                  *fn.attributes],
        "attributes": ATTRIBUTES,
        "scenarios": [{"dimension": fn.dim, "path": data_rel, "runs": runs}],
    }


def _write_function(tmp: Path, fid: int, fn: Function, folders: dict[str, str]) -> None:
    """One function's ``.dat`` and index per algorithm, into the export folder ``tmp``
    (``folders``: each label's folder, :func:`algorithm_folders`)."""
    fname = _safe(fn.name)
    for label, (info, runs) in fn.algorithms.items():
        algo_dir = tmp / folders[label]
        data_rel = f"data_f{fid}_{fname}/IOHprofiler_f{fid}_DIM{fn.dim}.dat"
        (algo_dir / data_rel).parent.mkdir(parents=True, exist_ok=True)
        lines, index_runs = [], []
        for inst, e, y, x in runs:
            lines.append(" ".join(ATTRIBUTES))
            lines += [f"{int(a)} {b:.10g}" for a, b in zip(e, y)]
            final = float(y[-1])
            index_runs.append({"instance": inst, "evals": int(e[-1]),
                               "best": {"evals": int(e[np.argmax(y <= final)]), "y": _finite(final), "x": x}})
        (algo_dir / data_rel).write_text("\n".join(lines) + "\n")
        index = _index(fid, fname, label, info, fn, data_rel, index_runs)
        (algo_dir / f"IOHprofiler_f{fid}_{fname}.json").write_text(json.dumps(index, indent=1, allow_nan=False) + "\n")


def ioh_export(results: Path, out: Path) -> list[Path]:
    """Write the IOHprofiler files of every experiment and suite under ``results`` into ``out``;
    returns the index files written."""
    folders = experiment_folders(results)
    out = check_out(out, results)
    loaded = [(f, fns) for f in folders if (fns := _load(f)) is not None]
    if not loaded:
        raise FkoptError(f"{results}: only studies/assembly results, which have no per-run traces to export")
    # the shared checks of the output folder (a folder, writable), once the inputs are good
    output_folder(out)

    functions = [fn for _, fns in loaded for fn in fns]
    folders = algorithm_folders(label for fn in functions for label in fn.algorithms)

    def write(tmp: Path) -> None:
        for fid, fn in enumerate(functions, start=1):
            _write_function(tmp, fid, fn, folders)
        (tmp / MARKER).write_text("fkopt export (IOHprofiler format; this file is the export's mark, "
                                  "not data)\n" + f"format: ioh\nfkopt: {fkopt.__version__}\nioh layout: {IOH_VERSION}\n"
                                  + "results:\n" + "".join(f"  {f}\n" for f, _ in loaded))

    write_atomically(out, write)
    return sorted(out.glob("*/IOHprofiler_f*.json"))
