"""The IOHprofiler data format -- what the ``ioh`` package's ``ioh.logger.Analyzer`` writes and
IOHanalyzer and iohinspector read: its constants and a reader. Below both of its users:
:mod:`fkopt.tools.export` writes it, :mod:`fkopt.kinbench.outside` imports other tools' runs with it.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from fkopt.errors import FkoptError
from fkopt.files import MAX_INPUT_BYTES, parse_json, read_input, short_token

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
    """Read IOHprofiler data (the ``ioh`` Analyzer logger's layout, which :func:`fkopt.tools.export.ioh_export` writes):
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
