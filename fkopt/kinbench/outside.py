"""Results of solvers that cannot run inside fkopt, ranked beside fkopt's.

A suite's ``outside:`` list names CSV files (relative to the suite file), one per solver::

    outside:
      - {solver: my-cmaes, track: black-box, file: outside/my-cmaes.csv}

The CSV has one row per logged evaluation count of a run, columns

==============  ==========================================================================
problem         a problem name of the suite (e.g. ``mao2017-3rps``)
set             a pose set (``uniform``, ``near-singular``, ``boundary``, ``printed``)
pose            the pose's index in its set file (0-based)
run             the run's index (0-based; any number of runs per pose)
evaluations     fitness evaluations used so far (an analytic Jacobian counts as one)
best_so_far     the best fitness found so far, on the problem's fitness (see docs/kinbench.md)
==============  ==========================================================================

Rows may log every evaluation or only improvements; a run's measures are read exactly as for
fkopt's solvers (:func:`fkopt.kinbench.runner.at_budget`): cut at the suite's budget, the
first evaluation count below each target. Every (problem, set, pose) instance the suite
selects must have at least one run, so all solvers are ranked on the same instances. The file's
SHA-256 is recorded in meta.json.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import FkoptError
from .budget import at_budget, budget_of

COLUMNS = ("problem", "set", "pose", "run", "evaluations", "best_so_far")


def outside_path(config, entry) -> Path:
    base = config._folder if config._folder is not None else Path(".")
    return Path(base) / entry.file


def digest(config, entry) -> str:
    return hashlib.sha256(outside_path(config, entry).read_bytes()).hexdigest()


def read_outside(config, k: int, dims: dict[str, int], instances: set[tuple[str, str, int]]) -> pd.DataFrame:
    """The run rows (as :func:`fkopt.kinbench.runner.run_rows` makes them) of ``config.outside[k]``."""
    entry = config.outside[k]
    path = outside_path(config, entry)
    where = f"outside[{k}].file: {path}"
    try:
        df = pd.read_csv(path, dtype={"problem": str, "set": str})
    except FileNotFoundError:
        raise FkoptError(f"{where}: not found") from None
    except (OSError, ValueError, pd.errors.ParserError) as err:
        raise FkoptError(f"{where}: unreadable CSV ({err})") from None
    missing = [c for c in COLUMNS if c not in df.columns]
    if missing:
        raise FkoptError(f"{where}: missing column '{missing[0]}'; needs {', '.join(COLUMNS)}")
    for col in ("pose", "run", "evaluations", "best_so_far"):
        vals = pd.to_numeric(df[col], errors="coerce")
        if vals.isna().any() or (col != "best_so_far" and ((vals < 0) | (vals % 1 != 0)).any()) \
                or (col == "best_so_far" and ((vals < 0) | ~np.isfinite(vals)).any()):
            row = int(np.flatnonzero(vals.isna() | (vals < 0))[0]) if (vals.isna() | (vals < 0)).any() else 0
            raise FkoptError(f"{where}: column '{col}' needs non-negative {'integers' if col != 'best_so_far' else 'finite numbers'} "
                             f"(row {row + 2})")
        df[col] = vals
    known = {(p, s, int(i)) for p, s, i in instances}
    got = set(zip(df["problem"], df["set"], df["pose"].astype(int)))
    lacking = sorted(known - got)
    if lacking:
        p, s, i = lacking[0]
        raise FkoptError(f"{where}: no run of problem {p}, set {s}, pose {i} (every instance of the suite needs one)")
    df = df[[key in known for key in zip(df["problem"], df["set"], df["pose"].astype(int))]]
    frames = []
    classes = {p.name: p.problem_class for p in config.problems}
    for (problem, name, pose, run), g in df.groupby(["problem", "set", "pose", "run"], sort=True):
        g = g.sort_values("evaluations", kind="stable")
        ev = g["evaluations"].to_numpy(dtype=float)
        hist = np.minimum.accumulate(g["best_so_far"].to_numpy(dtype=float))
        dim = dims[problem]
        m = at_budget(hist[None], ev[None], budget_of(config, dim), config.targets)
        frames.append({"problem": problem, "class": classes[problem], "set": name, "pose": int(pose),
                       "solver": entry.solver, "track": entry.track, "run": int(run), "dim": dim,
                       "budget": budget_of(config, dim), **{key: float(v[0]) for key, v in m.items()}})
    out = pd.DataFrame(frames)
    order = {(p.name, s): (i, j) for i, p in enumerate(config.problems) for j, s in enumerate(config.sets)}
    out["_o"] = [order[(p, s)] for p, s in zip(out["problem"], out["set"])]
    return out.sort_values(["_o", "pose", "run"], kind="stable").drop(columns="_o").reset_index(drop=True)
