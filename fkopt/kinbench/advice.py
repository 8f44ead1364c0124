"""Which solver to use for which problem, read off a stored suite's board (docs/robots.md).

For each problem of a suite folder: every solver's share of (pose, run) pairs that reached a
fitness target within the suite's budget, and its wall time per solve from ``timing.csv``,
best first (success, then time). docs/robots.md quotes this table for kinbench v2's problems,
and a test recomputes it from the stored ``runs.csv`` and ``timing.csv``, so the advice is the
board's, not an opinion.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.files import read_stored_csv


def success_by_problem(runs: pd.DataFrame, timing: pd.DataFrame, targets: list[str]) -> pd.DataFrame:
    """Columns problem, class, solver, success_<target> (share of (pose, run) pairs of the
    problem that reached each target) and ms_per_solve (timing.csv's time per solve: the
    older ``ms_per_solve`` or the amortised ``amortised_ms_per_run``), problems in runs.csv's order."""
    missing = [t for t in targets if f"evals_to_{t}" not in runs]
    if missing:
        raise ValueError(f"runs.csv: no column evals_to_{missing[0]} (targets: "
                         + ", ".join(c.removeprefix("evals_to_") for c in runs if c.startswith("evals_to_")) + ")")
    reached = {f"success_{t}": np.isfinite(runs[f"evals_to_{t}"].to_numpy(dtype=float)) for t in targets}
    table = (runs[["problem", "class", "solver"]].assign(**reached)
             .groupby(["problem", "class", "solver"], sort=False)[list(reached)].mean().reset_index())
    ms = "ms_per_solve" if "ms_per_solve" in timing else "amortised_ms_per_run"
    return table.merge(timing[["problem", "solver", ms]].rename(columns={ms: "ms_per_solve"}),
                       on=["problem", "solver"], how="left")


def advice_table(folder: str | Path, target: str = "1e-06", top: int = 3) -> pd.DataFrame:
    """Columns problem, class, solver, success (share reached ``target``), ms_per_solve; the
    ``top`` solvers of each problem, best first, problems in the order runs.csv lists them."""
    folder = Path(folder)
    runs = read_stored_csv(folder, "runs.csv")
    timing = read_stored_csv(folder, "timing.csv")
    try:
        table = success_by_problem(runs, timing, [target]).rename(columns={f"success_{target}": "success"})
    except ValueError as err:
        raise ValueError(f"{folder / 'runs.csv'}: {str(err).removeprefix('runs.csv: ')}") from None
    order = {p: i for i, p in enumerate(runs["problem"].unique())}
    table = table.assign(_p=table["problem"].map(order), _s=-table["success"]).sort_values(
        ["_p", "_s", "ms_per_solve"], kind="stable")
    return table.groupby("problem", sort=False).head(top).drop(columns=["_p", "_s"]).reset_index(drop=True)


def class_advice(runs: pd.DataFrame, timing: pd.DataFrame, targets: list[str], target: str) -> pd.DataFrame:
    """Per problem class, the solver to use: among the solvers run on every problem of the class,
    the best by mean success at ``target`` over the class's problems (each problem weighted
    alike), then by the median over problems of its time per solve. Columns class, problems,
    solver, success_<t> for each of ``targets`` (mean over problems), ms_per_solve (median),
    candidates (how many solvers ran every problem of the class)."""
    per = success_by_problem(runs, timing, targets)
    rows = []
    for cls, g in per.groupby("class", sort=False):
        n = g["problem"].nunique()
        full = g.groupby("solver", sort=False)["problem"].nunique()
        cand = g[g["solver"].isin(full[full == n].index)]
        if cand.empty:
            continue
        agg = cand.groupby("solver", sort=False).agg(
            **{f"success_{t}": (f"success_{t}", "mean") for t in targets}, ms_per_solve=("ms_per_solve", "median"))
        agg = agg.reset_index().sort_values([f"success_{target}", "ms_per_solve"], ascending=[False, True], kind="stable")
        rows.append({"class": cls, "problems": n, **agg.iloc[0].to_dict(), "candidates": len(agg)})
    return pd.DataFrame(rows)


def advice_markdown(table: pd.DataFrame) -> str:
    """The table as docs/robots.md prints it (one row per problem)."""
    lines = ["| problem | class | best | second | third |", "|---|---|---|---|---|"]
    for (problem, cls), rows in table.groupby(["problem", "class"], sort=False):
        cells = [f"{r.solver} {100 * r.success:.0f} %, {r.ms_per_solve:.3g} ms" for r in rows.itertuples()]
        lines.append(f"| {problem} | {cls} | " + " | ".join(cells + [""] * (3 - len(cells))) + " |")
    return "\n".join(lines)


def robots_summary(folder: str | Path, timeout_ms: float = 20.0) -> pd.DataFrame:
    """Per IK solver of a stored per-robot board (``leaderboard-robots.csv``) at ``timeout_ms``:
    the arms it ran on, its success at each rung of the ladder (mean over arms, and the worst
    arm at the board's rung) and its median time and median time ratio to the reference (median
    over arms); best first (mean success at the rung, then ratio). FK rows (the parallel
    mechanisms, another timeout ladder) are left out."""
    return summarise_board(read_stored_csv(folder, "leaderboard-robots.csv"), timeout_ms)


def summarise_throughput(throughput: pd.DataFrame) -> pd.DataFrame:
    """Per (solver, reference, batch size) of a board's ``throughput.csv``: the arms (or
    mechanisms) it answered, its queries per second and its ratio to the reference's one-per-call
    rate (median over the arms), and its success at each rung (mean over the arms, in per cent);
    the solvers in the file's order, batches ascending. An entry on the throughput track only
    (pytorch-kinematics) is on the page through this table."""
    success = [c for c in throughput.columns if c.startswith("success_")]
    g = throughput.groupby(["solver", "entry", "reference", "batch"], sort=False)
    out = g[success].mean().mul(100)
    out["arms"] = g["robot"].nunique()
    out["queries_per_s"] = g["queries_per_s"].median()
    out["reference_queries_per_s"] = g["reference_queries_per_s"].median()
    out["ratio"] = g["ratio"].median()
    order = {s: k for k, s in enumerate(throughput["solver"].unique())}
    out = out.reset_index()
    out = out.assign(_o=out["solver"].map(order)).sort_values(["_o", "reference", "batch"], kind="stable")
    return out.drop(columns="_o").reset_index(drop=True)[
        ["solver", "entry", "reference", "batch", "arms", "queries_per_s", "reference_queries_per_s", "ratio", *success]]


def fk_robots(board: pd.DataFrame) -> set:
    """The parallel mechanisms of a per-robot board (FK rows: they count other assembly modes)."""
    if "other_mode" not in board:
        return set()
    return set(board.loc[board["other_mode"].notna(), "robot"])


def summarise_board(board: pd.DataFrame, timeout_ms: float, fk: bool = False) -> pd.DataFrame:
    """:func:`robots_summary` of a board already read, over its IK rows (or, ``fk``, its FK
    rows) at ``timeout_ms``; extra columns of a newer board are ignored, and a ``cpu_ms_median``
    column, when the board has one, is summarised like the wall time (median over arms)."""
    fk_set = fk_robots(board)
    board = board[np.isclose(board["timeout_ms"], timeout_ms) & (board["robot"].isin(fk_set) == fk)]
    success = [c for c in board.columns if c.startswith("success_")]
    if board.empty:                      # no arm of this kind (IK or FK) at this timeout
        return pd.DataFrame(columns=["solver", "entry", *success, "worst_arm", "arms", "not_applicable",
                                     "median_ms", "median_ratio"])
    rung = f"success_{board['rung'].iloc[0]}"
    # a cell such as "not applicable: ..." (an arm a package cannot take) is no number: that arm
    # is left out of the entry's mean and count, never read as a zero
    numbers = [*success, "time_ms_median", "time_ratio_median", *(["cpu_ms_median"] if "cpu_ms_median" in board else [])]
    board = board.assign(**{c: pd.to_numeric(board[c], errors="coerce") for c in numbers})
    na = board[board[rung].isna()]                   # "not applicable" arms, counted apart
    board = board[board[rung].notna()]
    g = board.groupby(["solver", "entry"], sort=False)
    out = g[success].mean().mul(100)
    out["worst_arm"] = g[rung].min().mul(100)
    out["arms"] = g["robot"].nunique()
    out["not_applicable"] = na.groupby(["solver", "entry"], sort=False)["robot"].nunique() \
        .reindex(out.index).fillna(0).astype(int)
    out["median_ms"] = g["time_ms_median"].median()
    if "cpu_ms_median" in board:
        out["cpu_ms_median"] = g["cpu_ms_median"].median()
    out["median_ratio"] = g["time_ratio_median"].median()
    out = out.reset_index().sort_values([rung, "median_ratio"], ascending=[False, True], kind="stable")
    return out.reset_index(drop=True)


def family_advice(board: pd.DataFrame, families: dict[str, str]) -> pd.DataFrame:
    """Per arm family (``families``: robot -> its problem class, e.g. serial-ik-7dof), the
    solver to use at the family's largest timeout: among the entries that take every arm of the
    family (a package that cannot take one of them, a "not applicable" cell, is no answer for
    that arm's owner), the first row of :func:`summarise_board` over the family's arms (success
    at the board's rung, mean over the arms, then median time ratio); the first row of all when
    no entry takes every arm. Columns family, arms (names), timeout_ms, then the summary's
    columns of that solver, then ``leads_where_it_applies``: the first row of all when it is
    another entry (one that cannot take every arm), its success, median time and arm count, else
    empty."""
    fk_set = fk_robots(board)
    rows = []
    for family in dict.fromkeys(families[r] for r in board["robot"].unique() if r in families):
        arms = [r for r in board["robot"].unique() if families.get(r) == family]
        sub = board[board["robot"].isin(arms)]
        timeout = float(sub["timeout_ms"].max())
        best = summarise_board(sub, timeout, fk=arms[0] in fk_set)
        if best.empty:
            continue
        whole = best[best["not_applicable"] == 0]
        row = (whole if not whole.empty else best).iloc[0].to_dict()
        top = best.iloc[0]
        top_success = top[f"success_{sub['rung'].iloc[0]}"]
        # the entry that leads on the arms it takes, when that is not every arm: named beside the
        # advice, so that a faster package is not hidden by the arms it cannot take
        partial = "" if top["solver"] == row["solver"] else (
            f"{top['solver']}: {top_success:.1f} %, {top['median_ms']:.3g} ms "
            f"on {int(top['arms'])} of {len(arms)} arms (not applicable on {int(top['not_applicable'])})")
        rows.append({"family": family, "arms": ", ".join(arms), "timeout_ms": timeout,
                     **{k: v for k, v in row.items() if k != "arms"}, "leads_where_it_applies": partial})
    return pd.DataFrame(rows)


def robots_markdown(table: pd.DataFrame, timeout_ms: float = 20.0) -> str:
    """The summary as README prints it."""
    success = [c for c in table.columns if c.startswith("success_")]
    rungs = " / ".join(c.removeprefix("success_").replace("_", ", ") for c in success)
    cpu = "cpu_ms_median" in table
    lines = [f"| solver | entry | arms | success % at {rungs} (mean over arms) | worst arm % | median ms | "
             + ("median CPU ms per call | " if cpu else "") + "median ratio to rtb `ik_LM` |",
             "|---|---|---|---|---|---|---|" + ("---|" if cpu else "")]
    for _, r in table.iterrows():
        pct = " / ".join(f"{r[c]:.0f}" for c in success)
        na = int(r.get("not_applicable", 0) or 0)
        arms = f"{r['arms']}" + (f" (not applicable: {na})" if na else "")
        lines.append(f"| {r['solver']} | {r['entry']} | {arms} | {pct} | {r['worst_arm']:.0f} | "
                     f"{r['median_ms']:.3g} | " + (f"{r['cpu_ms_median']:.3g} | " if cpu else "")
                     + f"{r['median_ratio']:.3g} |")
    return "\n".join(lines)


def fk_sentence(folder: str | Path, timeout_ms: float = 500.0) -> str:
    """The FK rows of a stored per-robot board at ``timeout_ms`` as README's one sentence: per
    parallel mechanism, each solver's success at the generating pose (the board's rung) and, in
    brackets, the share solved in another assembly mode; best first."""
    board = read_stored_csv(folder, "leaderboard-robots.csv")
    board = board[board["robot"].isin(fk_robots(board)) & np.isclose(board["timeout_ms"], timeout_ms)]
    parts = []
    for robot, rows in board.groupby("robot", sort=False):
        rung = f"success_{rows['rung'].iloc[0]}"
        rows = rows.sort_values(rung, ascending=False, kind="stable")
        cells = [f"`{r['solver']}` {100 * r[rung]:.0f} % (+{100 * r['other_mode']:.0f} % another mode)"
                 for _, r in rows.iterrows()]
        parts.append(f"FK of {robot} at {timeout_ms:g} ms, at the generating pose: " + ", ".join(cells))
    return "; ".join(parts) + "."
