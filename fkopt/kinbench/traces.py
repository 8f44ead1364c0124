"""Each run's best-so-far trace within the budget: a suite's ``trace.csv.gz``.

One row per improvement of a run's best-so-far fitness within the suite's budget, at the exact
evaluation at which it happened, as far as the solver reports it (the rules of an experiment's
trace, :mod:`fkopt.run.trace`, whose :func:`~fkopt.run.trace.run_trace` builds
the rows) -- what :func:`suite_functions` turns into IOHprofiler data for ``fkopt export``:

=============  ==========================================================================
problem        problem name
set            pose set
pose           pose index within its set (0-based)
solver         solver label (fkopt's solvers, then the outside ones)
run            run index
evaluations    the evaluation's number, counted from 1
best_fitness   best-so-far fitness from then on (``inf``: no fitness known yet)
=============  ==========================================================================

Rows are in the order of ``runs.csv`` (per run, by evaluations). The cut is the runs.csv
measures' (:func:`fkopt.kinbench.budget.at_budget`): a run's rows end at the evaluations it had
used at its last iteration within the budget B, with the best-so-far fitness there -- so a run's
last row is runs.csv's ``evaluations`` and ``fitness``. Row 1 of every run is evaluation 1 (IOH
readers start a run there); when the solver reports no fitness value there -- an exact solver's
first value is its answer, at the evaluations the answer cost; an outside log may start later --
its best_fitness is ``inf``. A run with no iteration within B (an exact solver that needed more
than B) has the two rows (1, inf) and (B, inf): it spent the budget without an answer (runs.csv
records B evaluations and fitness inf for it). Outside results (:mod:`fkopt.kinbench.outside`)
get rows from their logged (evaluations, best so far) pairs the same way, an evaluation count of
0 taken as 1.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.errors import FkoptError
from fkopt.run.iohformat import Function, stored_runs, trace_runs
from fkopt.run.trace import FILE, history_events, read_trace, run_trace
from fkopt.kinbench.budget import budget_of, last_within
from fkopt.kinbench.outside import in_suite_order, logged_runs

__all__ = ["FILE", "COLUMNS", "budget_trace", "task_trace", "outside_trace", "suite_trace", "suite_functions"]

COLUMNS = ("problem", "set", "pose", "solver", "run", "evaluations", "best_fitness")
#: the columns that name a run
KEYS = ["problem", "set", "pose", "solver", "run"]


def budget_trace(events, evaluations: np.ndarray, budget: int):
    """The trace rows of each run cut at ``budget`` (module docstring): (row, evaluation, best
    fitness) arrays sorted by row and evaluation, from ``events`` (row, evaluation, fitness)
    improvements sorted by row and evaluation and ``evaluations`` (rows, T + 1) the cumulative
    counts per iteration."""
    evaluations = np.asarray(evaluations, dtype=np.int64)
    last = last_within(evaluations, budget)
    ok = last >= 0
    r, _, e, f = run_trace(events, evaluations, np.maximum(last, 0))
    keep = ok[r]
    r, e, f = r[keep], np.maximum(e[keep], 1), f[keep]
    starts = np.ones(len(ok), dtype=bool)               # runs whose first row is not evaluation 1
    starts[r[e == 1]] = False
    lead = np.flatnonzero(starts)
    empty = np.flatnonzero(~ok)
    r = np.concatenate([lead, r, empty])
    e = np.concatenate([np.ones(len(lead), np.int64), e, np.full(len(empty), max(int(budget), 1), np.int64)])
    f = np.concatenate([np.full(len(lead), np.inf), f, np.full(len(empty), np.inf)])
    order = np.lexsort((e, r))                          # stable: of equal (row, evaluation), the last
    r, e, f = r[order], e[order], f[order]              # row is the best value there
    last_of = np.r_[(r[1:] != r[:-1]) | (e[1:] != e[:-1]), True]
    return r[last_of], e[last_of], f[last_of]


def task_trace(result, budget: int) -> dict:
    """The trace of every (case, run) row of a suite task's batched ``result``, JSON-able (the
    task record's ``"trace"``): ``row`` (case x runs + run, the row of the task's run rows),
    ``evaluations``, ``best_fitness``."""
    ev = np.asarray(result.evaluation_history).reshape(-1, result.evaluation_history.shape[-1])
    events = result.events if result.events is not None else history_events(
        np.asarray(result.history).reshape(ev.shape), ev)
    r, e, f = budget_trace(events, ev, budget)
    return {"row": r.tolist(), "evaluations": e.tolist(), "best_fitness": f.tolist()}


def outside_trace(config, k: int, dims: dict[str, int], instances: set[tuple[str, str, int]],
                  files=None) -> pd.DataFrame:
    """The trace rows (:mod:`fkopt.kinbench.traces`) of ``config.outside[k]``'s runs, cut at the
    budget as :func:`~fkopt.kinbench.outside.read_outside`'s measures are."""
    entry = config.outside[k]
    frames = []
    for problem, name, pose, run, ev, hist in logged_runs(config, k, instances, files):
        keep = np.r_[True, hist[1:] < hist[:-1]]            # the improvements, at their logged counts
        events = (np.zeros(int(keep.sum()), np.intp), ev[keep].astype(np.int64), hist[keep])
        _, e, f = budget_trace(events, ev[None], budget_of(config, dims[problem]))
        frames.append(pd.DataFrame({"problem": problem, "set": name, "pose": pose, "solver": entry.solver,
                                    "run": run, "evaluations": e, "best_fitness": f}))
    return in_suite_order(config, pd.concat(frames, ignore_index=True))[list(COLUMNS)]


def suite_trace(config, done: list[dict], runs: pd.DataFrame, files=None) -> pd.DataFrame:
    """The trace table of a suite: its tasks' traces (``done``: the task records, in the order
    of their run rows in ``runs``) and the outside results' (read again from their files, in
    ``files``: the suite file's folder)."""
    frames = []
    for rec in done:
        t = rec["trace"]
        try:
            frame = rec["rows"].iloc[np.asarray(t["row"], dtype=np.intp)][KEYS].reset_index(drop=True)
            frame["evaluations"] = np.asarray(t["evaluations"], dtype=np.int64)
            frame["best_fitness"] = np.asarray(t["best_fitness"], dtype=float)
        except (KeyError, IndexError, TypeError, ValueError) as err:     # a damaged task file (--resume)
            raise FkoptError(f"task (problem {rec['problem']}, solver {rec['solver']}): its trace does not fit "
                             f"its run rows ({type(err).__name__}: {str(err)[:120]}); rerun without --resume") from None
        frames.append(frame)
    if config.outside:
        dims = dict(zip(runs["problem"], runs["dim"]))
        instances = set(zip(runs["problem"], runs["set"], runs["pose"]))
        frames += [outside_trace(config, k, dims, instances, files) for k in range(len(config.outside))]
    if not frames:
        return pd.DataFrame(columns=list(COLUMNS))
    return pd.concat(frames, ignore_index=True)[list(COLUMNS)]


def suite_functions(folder: Path, meta: dict) -> list[Function]:
    """A suite folder as IOH functions for ``fkopt export`` (``Kind.ioh_functions``; the layout:
    :mod:`fkopt.tools.export`): one function per problem, in the suite's order, one instance per
    (set, pose) in set-then-pose order, one algorithm per solver (outside solvers included)."""
    path, config = folder / "meta.json", meta["config"]
    problems, sets = config.get("problems"), config.get("sets")
    if not (isinstance(problems, list) and all(isinstance(p, dict) and isinstance(p.get("name"), str) for p in problems)
            and isinstance(sets, list) and isinstance(config.get("name"), str)):
        raise FkoptError(f"{path}: 'config' lacks the suite's 'name', 'problems' or 'sets'")
    if not (folder / FILE).is_file():
        raise FkoptError(f"{folder}: no {FILE} (suite results written before fkopt kept run traces); "
                         "rerun the suite to export it")
    trace = read_trace(folder, columns=COLUMNS)
    runs = stored_runs(folder, KEYS + ["dim", "track"], ("problem", "set", "solver", "track"))
    groups = trace_runs(folder, trace, runs, KEYS, lambda k: f"run {k[4]} of solver '{k[3]}', problem "
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
            info.update(track=str(rs["track"].iloc[0]))
            order = sorted(zip(rs["set"], rs["pose"], rs["run"]), key=lambda k: (number[k[:2]], k[2]))
            runs_l = []
            for s, p, r in order:
                rows = groups[(problem["name"], s, p, label, r)]
                runs_l.append((number[(s, p)], rows["evaluations"].to_numpy(), rows["best_fitness"].to_numpy(), []))
            fn.algorithms[label] = (info, runs_l)
        out.append(fn)
    return out
