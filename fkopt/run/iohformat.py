"""The IOHprofiler data format -- what the ``ioh`` package's ``ioh.logger.Analyzer`` writes and
IOHanalyzer and iohinspector read: its constants, its writer (:class:`Function`,
:func:`write_function`), its reader (:func:`read_ioh`), and the checked reading of a stored
folder's runs and trace that every kind's loader shares (:func:`stored_runs`, :func:`trace_runs`).
It knows no kind: a kind turns its stored folder into :class:`Function` objects
(``Kind.ioh_functions``, :mod:`fkopt.run.tasks`), :mod:`fkopt.tools.export` writes them, and
:mod:`fkopt.kinbench.outside` imports other tools' runs with the reader.
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
from fkopt.files import (MAX_INPUT_BYTES, csv_numbers, file_names, parse_json, read_input, read_stored_csv,
                         short_token)
from fkopt.run.trace import FILE

#: The ioh release whose ``ioh.logger.Analyzer`` output the index layout mirrors.
IOH_VERSION = "0.4.2"
#: The columns of a ``.dat`` file.
ATTRIBUTES = ["evaluations", "raw_y"]
#: Largest evaluation count read: every integer up to 2^53 is exact in a double.
MAX_EVALUATIONS = 2 ** 53
#: Largest index file read (bytes); an index lists runs, not their data.
MAX_INDEX_BYTES = 16 << 20


def _index_fields(index, where: str) -> tuple[str, str, list]:
    """(algorithm name, function name, scenarios) of an index file, their types checked."""
    if not isinstance(index, dict):
        raise FkoptError(f"{where}: must be a JSON mapping (an IOHprofiler_f*.json index)")
    algo = index.get("algorithm")
    if not isinstance(algo, dict) or not isinstance(algo.get("name"), str) or not algo["name"]:
        raise FkoptError(f"{where}: field 'algorithm.name' must be text (the algorithm's name)")
    fname = index.get("function_name")
    if not isinstance(fname, str) or not fname:
        raise FkoptError(f"{where}: field 'function_name' must be text (<problem>__<set>), got a "
                         f"{type(fname).__name__}")
    scenarios = index.get("scenarios")
    if not isinstance(scenarios, list):
        raise FkoptError(f"{where}: field 'scenarios' must be a list of {{path, runs}}")
    return algo["name"], fname, scenarios


def _runs(sc, where: str, k: int) -> list:
    runs = sc.get("runs")
    if not isinstance(runs, list):
        raise FkoptError(f"{where}: field 'scenarios[{k}].runs' must be a list of {{instance, ...}}")
    for j, run in enumerate(runs):
        inst = run.get("instance") if isinstance(run, dict) else None
        if not isinstance(inst, int) or isinstance(inst, bool) or not 1 <= inst <= MAX_EVALUATIONS:
            raise FkoptError(f"{where}: field 'scenarios[{k}].runs[{j}].instance' must be an integer >= 1 "
                             "(the pose index + 1)")
    return runs


def _dat_blocks(data: bytes, where: str) -> list[list[tuple[float, float]]]:
    """The runs of a ``.dat`` file: one block per ``evaluations raw_y`` header, each line two
    numbers (an integer count in [0, 2^53], a number); no cell is quoted in an error."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise FkoptError(f"{where}: not UTF-8 text (offset {err.start})") from None
    blocks: list[list[tuple[float, float]]] = []
    for n, line in enumerate(text.splitlines(), 1):
        if line.startswith("evaluations"):
            blocks.append([])
            continue
        if not line.strip():
            continue
        if not blocks:
            raise FkoptError(f"{where}: line {n}: data before the first 'evaluations raw_y' header")
        cells = line.split()
        try:
            e, y = float(cells[0]), float(cells[1])
        except (IndexError, ValueError):
            raise FkoptError(f"{where}: line {n}: needs two numbers (evaluations raw_y)") from None
        if not (0 <= e <= MAX_EVALUATIONS and e == int(e)):
            raise FkoptError(f"{where}: line {n}: evaluations must be an integer in [0, 2^53]")
        blocks[-1].append((e, y))
    return blocks


def read_ioh(folder: Path, max_bytes: int = MAX_INPUT_BYTES) -> dict:
    """Read IOHprofiler data (the ``ioh`` Analyzer logger's layout, which :func:`write_function` writes):
    ``{(algorithm, function_name, instance): [(array of (evaluations, y) rows, run info), ...]}``.
    What :mod:`fkopt.kinbench.outside` imports results of other tools with; fkopt's own tests read
    the export with iohinspector instead.

    Data of another tool, so hostile: every file is read with :func:`fkopt.files.read_input`'s
    bounds and must lie inside ``folder`` (a ``scenarios[].path`` of ``../../x`` or ``/etc/x`` is
    refused); the index fields and ``.dat`` lines are checked; every failure is one
    :class:`~fkopt.errors.FkoptError` line naming the file and the field, quoting at most a short
    sanitised token of it."""
    folder = Path(folder)
    out: dict = {}
    for index_file in sorted(folder.glob("*/IOHprofiler_f*.json")):
        where = str(index_file)
        raw = read_input(index_file, MAX_INDEX_BYTES, within=folder)
        algorithm, fname, scenarios = _index_fields(parse_json(raw, where), where)
        for k, sc in enumerate(scenarios):
            if not isinstance(sc, dict) or not isinstance(sc.get("path"), str) or not sc["path"]:
                raise FkoptError(f"{where}: field 'scenarios[{k}].path' must be the .dat file's path (text)")
            runs = _runs(sc, where, k)
            dat = index_file.parent / sc["path"]
            field = f"{where}: scenarios[{k}].path '{short_token(sc['path'])}'"
            blocks = _dat_blocks(read_input(dat, max_bytes, field=field, within=folder), str(dat))
            if len(blocks) != len(runs):
                raise FkoptError(f"{where}: scenarios[{k}]: {len(runs)} runs indexed, {len(blocks)} in the .dat")
            for run, block in zip(runs, blocks):
                key = (algorithm, fname, run["instance"])
                out.setdefault(key, []).append((np.array(block, dtype=float).reshape(-1, 2), run))
    return out


# -- writing ----------------------------------------------------------------------------------------
@dataclass
class Function:
    """One IOH function of an exported folder: an experiment, or one problem of a suite."""

    name: str                        # function_name (made file-safe when written)
    dim: int
    instances: list[str]             # the label of instance i + 1
    attributes: list[dict]           # experiment attributes after ``instances``
    #: algorithm label -> (``algorithm.info`` content without fkopt's version, which the writer
    #: adds; runs: (instance, evaluations, best-so-far, x))
    algorithms: dict[str, tuple[dict, list]] = field(default_factory=dict)


def safe_name(text: str) -> str:
    """``text`` as a file name's part: runs of other characters than ``A-Za-z0-9_.-`` as ``-``."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "-", str(text)).strip("-") or "x"


def algorithm_folders(labels) -> dict[str, str]:
    """The export's folder of each algorithm label, one per label (:func:`fkopt.files.file_names`):
    ``pso+lm`` and an outside solver ``pso-lm`` never share a folder (nor its index files)."""
    return file_names(labels, allowed="A-Za-z0-9_.-", sep="-")


def _finite(y: float):
    """A best value for the JSON index: a number, or null when none was found (strict JSON has
    no infinity)."""
    return y if np.isfinite(y) else None


def _index(fid: int, fname: str, label: str, info: dict, fn: Function, data_rel: str, runs: list) -> dict:
    return {
        "version": IOH_VERSION, "suite": "fkopt", "function_id": fid, "function_name": fname,
        "maximization": False,
        "algorithm": {"name": label, "info": json.dumps({**info, "fkopt": fkopt.__version__})},
        "experiment_attributes": [{"instances": "; ".join(f"{i}={c}" for i, c in enumerate(fn.instances, start=1))},
                                  *fn.attributes],
        "attributes": ATTRIBUTES,
        "scenarios": [{"dimension": fn.dim, "path": data_rel, "runs": runs}],
    }


def write_function(folder: Path, fid: int, fn: Function, folders: dict[str, str]) -> None:
    """One function's ``.dat`` and index per algorithm, into the export folder ``folder``
    (``folders``: each label's folder, :func:`algorithm_folders`)."""
    fname = safe_name(fn.name)
    for label, (info, runs) in fn.algorithms.items():
        algo_dir = folder / folders[label]
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


# -- a stored folder's runs and trace, checked (what every kind's loader shares) ------------------------
def stored_runs(folder: Path, columns, labels) -> pd.DataFrame:
    """``folder``'s runs.csv with ``columns`` (else one line naming the missing ones), the
    ``labels`` columns as text and its ``run``, ``pose`` and ``dim`` columns as integers."""
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


def trace_runs(folder: Path, trace: pd.DataFrame, runs: pd.DataFrame, keys: list[str], what) -> dict:
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
