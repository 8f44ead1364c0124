"""Results of solvers that cannot run inside fkopt, ranked beside fkopt's.

A suite's ``outside:`` list names, per solver, a CSV file or an IOHprofiler folder (paths
relative to the suite file)::

    outside:
      - {solver: my-cmaes, track: black-box, file: outside/my-cmaes.csv}
      - {solver: ioh-de, track: black-box, ioh: outside/ioh-runs, algorithm: DE}

**CSV**: one row per logged evaluation count of a run, columns

==============  ==========================================================================
problem         a problem name of the suite (e.g. ``mao2017-3rps``)
set             a pose set (``uniform``, ``near-singular``, ``boundary``, ``printed``)
pose            the pose's index in its set file (0-based)
run             the run's index (0-based; any number of runs per pose)
evaluations     fitness evaluations used so far (an analytic Jacobian counts as one)
best_so_far     the best fitness found so far, on the problem's fitness (see docs/kinbench.md)
==============  ==========================================================================

**IOH** (what IOHexperimenter's ``Analyzer`` logger writes, read by
:func:`fkopt.run.iohformat.read_ioh`): ``ioh`` is the logger's ``root`` (a folder of run folders, each
with its ``IOHprofiler_f*.json`` index and ``.dat`` files); the function name is ``<problem>__<set>`` (two underscores),
the instance is the pose index + 1, each logged run one run; the ``.dat`` lines are
``evaluations raw_y`` with raw_y the problem's fitness (minimised). ``algorithm`` picks one
algorithm of the folder (needed when it holds several).

Rows may log every evaluation or only improvements; a run's measures are read exactly as for
fkopt's solvers (:func:`fkopt.kinbench.budget.at_budget`): cut at the suite's budget, the first
evaluation count below each target; their improvements within the budget join the suite's
``trace.csv.gz`` (:func:`fkopt.kinbench.traces.outside_trace`). Every (problem, set, pose) instance the suite selects must
have at least one run, so all solvers are ranked on the same instances. The SHA-256 of the file
(of every file of the folder) is recorded in meta.json.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.errors import FkoptError
from fkopt.files import MAX_INPUT_BYTES, csv_numbers, read_csv, read_input
from fkopt.run.config_base import files_folder
from fkopt.run.record import run_record
from fkopt.kinbench.budget import at_budget, budget_of
from fkopt.run.iohformat import read_ioh

COLUMNS = ("problem", "set", "pose", "run", "evaluations", "best_so_far")
IOH_SEPARATOR = "__"


def outside_path(config, entry, files: Path | None = None) -> Path:
    """An outside entry's file or folder, in ``files`` (default: the suite file's folder,
    :func:`fkopt.kinds.experiment.config.files_folder`)."""
    base = files if files is not None else files_folder(config)
    return Path(base if base is not None else ".") / (entry.file or entry.ioh)


#: Largest integer in the pose, run and evaluations columns: every integer up to 2^53 is exact
#: in a double and fits int64 (1e300 evaluations would wrap to a count of 1 when cast).
MAX_COUNT = 2 ** 53


def digest(config, entry, files: Path | None = None) -> str:
    """SHA-256 of the file (of every file of the IOH folder, by relative path), read bounded."""
    path = outside_path(config, entry, files)
    files = [path] if entry.file else sorted(p for p in path.rglob("*") if p.is_file())
    h = hashlib.sha256()
    for f in files:
        data = read_input(f, MAX_INPUT_BYTES, within=None if entry.file else path, unpack=False)
        h.update(str(f.relative_to(path) if entry.ioh else f.name).encode() + b"\0" + data)
    return h.hexdigest()


def read_csv_columns(path: Path, where: str, columns, dtype: dict, needs: str | None = None) -> pd.DataFrame:
    """A submitted CSV (``.csv`` or ``.csv.gz``) with the ``columns`` it must have, read with
    :func:`fkopt.files.read_input`'s bounds (a regular file, size and unpacked size capped); a
    missing file, an unreadable one or a missing column is one line (``needs``: how the message
    lists what is needed)."""
    if not path.exists() and not path.is_symlink():
        raise FkoptError(f"{where}: not found")
    df = read_csv(path, MAX_INPUT_BYTES, field=where.partition(": ")[0], dtype=dtype)   # bytes and memory bounded
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise FkoptError(f"{where}: missing column '{missing[0]}'; needs {needs or ', '.join(columns)}")
    return df


def _csv_log(path: Path, where: str) -> pd.DataFrame:
    return read_csv_columns(path, where, COLUMNS, {"problem": str, "set": str})


def _ioh_log(path: Path, where: str, algorithm: str | None) -> pd.DataFrame:
    if not path.is_dir():
        raise FkoptError(f"{where}: not a folder")
    data = read_ioh(path)
    algos = sorted({a for a, _, _ in data})
    if not algos:
        raise FkoptError(f"{where}: no IOHprofiler_f*.json index files found")
    if algorithm is None and len(algos) > 1:
        raise FkoptError(f"{where}: holds algorithms {', '.join(algos)}; name one with 'algorithm:'")
    pick = algorithm or algos[0]
    if pick not in algos:
        raise FkoptError(f"{where}: algorithm '{pick}' not found; it holds {', '.join(algos)}")
    rows = []
    for (algo, fname, instance), runs in sorted(data.items(), key=lambda kv: kv[0][1:]):
        if algo != pick:
            continue
        problem, sep, name = fname.partition(IOH_SEPARATOR)
        if not sep:
            raise FkoptError(f"{where}: function name '{fname}' is not <problem>{IOH_SEPARATOR}<set>")
        for run, (block, _) in enumerate(runs):
            rows += [(problem, name, int(instance) - 1, run, e, y) for e, y in block]
    return pd.DataFrame(rows, columns=list(COLUMNS))


def logged_runs(config, k: int, instances: set[tuple[str, str, int]], files: Path | None = None):
    """``config.outside[k]``'s file, checked, as one (problem, set, pose, run, evaluations,
    best-so-far) tuple per run of a selected instance (sorted keys; evaluations sorted, the
    best-so-far accumulated)."""
    entry = config.outside[k]
    path = outside_path(config, entry, files)
    where = f"outside[{k}].{'file' if entry.file else 'ioh'}: {path}"
    df = _csv_log(path, where) if entry.file else _ioh_log(path, where, entry.algorithm)
    for col in ("pose", "run", "evaluations", "best_so_far"):
        vals = pd.Series(csv_numbers(df[col]), index=df.index)     # a 400-digit integer: inf, refused below
        integer = col != "best_so_far"
        bad = vals.isna() | (vals < 0) | (~np.isfinite(vals.fillna(0)))
        if integer:       # range-checked before any cast to int
            bad |= (vals.fillna(0) % 1 != 0) | (vals.fillna(0) > MAX_COUNT)
        if bad.any():
            need = "integers in [0, 2^53]" if integer else "finite numbers"
            raise FkoptError(f"{where}: column '{col}' needs non-negative {need} "
                             f"(row {int(np.flatnonzero(bad)[0]) + 2})")
        df[col] = vals
    got = set(zip(df["problem"], df["set"], df["pose"].astype(int)))
    lacking = sorted(instances - got)
    if lacking:
        p, s, i = lacking[0]
        raise FkoptError(f"{where}: no run of problem {p}, set {s}, pose {i} (every instance of the suite needs one)")
    df = df[[key in instances for key in zip(df["problem"], df["set"], df["pose"].astype(int))]]
    for (problem, name, pose, run), g in df.groupby(["problem", "set", "pose", "run"], sort=True):
        g = g.sort_values("evaluations", kind="stable")
        ev = g["evaluations"].to_numpy(dtype=float)
        yield problem, name, int(pose), int(run), ev, np.minimum.accumulate(g["best_so_far"].to_numpy(dtype=float))


def in_suite_order(config, out: pd.DataFrame) -> pd.DataFrame:
    """``out`` sorted by problem and set in the suite's order, then pose and run (and evaluations)."""
    order = {(p.name, s): (i, j) for i, p in enumerate(config.problems) for j, s in enumerate(config.sets)}
    out["_o"] = [order[(p, s)] for p, s in zip(out["problem"], out["set"])]
    keys = ["_o", "pose", "run"] + (["evaluations"] if "best_fitness" in out.columns else [])
    return out.sort_values(keys, kind="stable").drop(columns="_o").reset_index(drop=True)


def read_outside(config, k: int, dims: dict[str, int], instances: set[tuple[str, str, int]],
                 files: Path | None = None) -> pd.DataFrame:
    """The run rows (as :func:`fkopt.kinbench.runner.run_rows` makes them) of ``config.outside[k]``."""
    entry = config.outside[k]
    frames = []
    classes = {p.name: p.problem_class for p in config.problems}
    for problem, name, pose, run, ev, hist in logged_runs(config, k, instances, files):
        dim = dims[problem]
        m = at_budget(hist[None], ev[None], budget_of(config, dim), config.targets)
        frames.append({"problem": problem, "class": classes[problem], "set": name, "pose": pose,
                       "solver": entry.solver, "track": entry.track, "run": run, "dim": dim,
                       "budget": budget_of(config, dim), **{key: float(v[0]) for key, v in m.items()}})
    rows = pd.DataFrame(frames)
    return in_suite_order(config, run_record("suite", {c: rows[c].to_numpy() for c in rows.columns}))
