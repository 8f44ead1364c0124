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


def advice_table(folder: str | Path, target: str = "1e-06", top: int = 3) -> pd.DataFrame:
    """Columns problem, class, solver, success (share reached ``target``), ms_per_solve; the
    ``top`` solvers of each problem, best first, problems in the order runs.csv lists them."""
    folder = Path(folder)
    runs = pd.read_csv(folder / "runs.csv")
    timing = pd.read_csv(folder / "timing.csv")
    column = f"evals_to_{target}"
    if column not in runs:
        raise ValueError(f"{folder / 'runs.csv'}: no column {column} (targets: "
                         + ", ".join(c.removeprefix("evals_to_") for c in runs if c.startswith("evals_to_")) + ")")
    runs = runs.assign(reached=np.isfinite(runs[column].to_numpy(dtype=float)))
    table = (runs.groupby(["problem", "class", "solver"], sort=False)["reached"].mean().rename("success")
             .reset_index().merge(timing[["problem", "solver", "ms_per_solve"]], on=["problem", "solver"], how="left"))
    order = {p: i for i, p in enumerate(runs["problem"].unique())}
    table = table.assign(_p=table["problem"].map(order), _s=-table["success"]).sort_values(
        ["_p", "_s", "ms_per_solve"], kind="stable")
    return table.groupby("problem", sort=False).head(top).drop(columns=["_p", "_s"]).reset_index(drop=True)


def advice_markdown(table: pd.DataFrame) -> str:
    """The table as docs/robots.md prints it (one row per problem)."""
    lines = ["| problem | class | best | second | third |", "|---|---|---|---|---|"]
    for (problem, cls), rows in table.groupby(["problem", "class"], sort=False):
        cells = [f"{r.solver} {100 * r.success:.0f} %, {r.ms_per_solve:.3g} ms" for r in rows.itertuples()]
        lines.append(f"| {problem} | {cls} | " + " | ".join(cells + [""] * (3 - len(cells))) + " |")
    return "\n".join(lines)


def robots_summary(folder: str | Path, timeout_ms: float = 20.0) -> pd.DataFrame:
    """Per IK solver of a stored per-robot board (``leaderboard-robots.csv``) at ``timeout_ms``:
    the arms it ran on and those it cannot take ("not applicable" cells, counted apart, never as
    zeros), its success at each rung of the ladder (mean over the arms it ran on, and the worst
    arm at the board's rung) and its median time, median CPU time per call (boards from version 2
    on) and median time ratio to the reference (median over arms); best first (mean success at
    the rung, then ratio). FK rows (the parallel mechanisms, another timeout ladder) are left out."""
    board = pd.read_csv(Path(folder) / "leaderboard-robots.csv")
    fk_robots = set(board.loc[board["other_mode"].notna(), "robot"])      # FK rows count other modes
    board = board[np.isclose(board["timeout_ms"], timeout_ms) & ~board["robot"].isin(fk_robots)]
    success = [c for c in board.columns if c.startswith("success_")]
    rung = f"success_{board['rung'].iloc[0]}"
    na = (board["not_applicable"].fillna("").astype(str) != "") if "not_applicable" in board else \
        pd.Series(False, index=board.index)
    ran = board[~na]
    g = ran.groupby(["solver", "entry"], sort=False)
    out = g[success].mean().mul(100)
    out["worst_arm"] = g[rung].min().mul(100)
    out["arms"] = g["robot"].nunique()
    out["not_applicable"] = board[na].groupby(["solver", "entry"], sort=False)["robot"].nunique() \
        .reindex(out.index).fillna(0).astype(int)
    out["median_ms"] = g["time_ms_median"].median()
    if "cpu_ms_median" in ran:
        out["median_cpu_ms"] = g["cpu_ms_median"].median()
    out["median_ratio"] = g["time_ratio_median"].median()
    out = out.reset_index().sort_values([rung, "median_ratio"], ascending=[False, True], kind="stable")
    return out.reset_index(drop=True)


def robots_markdown(table: pd.DataFrame, timeout_ms: float = 20.0) -> str:
    """The summary as README prints it."""
    success = [c for c in table.columns if c.startswith("success_")]
    rungs = " / ".join(c.removeprefix("success_").replace("_", ", ") for c in success)
    cpu = "median_cpu_ms" in table
    lines = [f"| solver | entry | arms | success % at {rungs} (mean over arms) | worst arm % | median ms | "
             + ("median CPU ms per call | " if cpu else "") + "median ratio to rtb `ik_LM` |",
             "|---|---|---|---|---|---|---|" + ("---|" if cpu else "")]
    for _, r in table.iterrows():
        pct = " / ".join(f"{r[c]:.0f}" for c in success)
        na = int(r.get("not_applicable", 0) or 0)
        arms = f"{r['arms']}" + (f" (not applicable: {na})" if na else "")
        lines.append(f"| {r['solver']} | {r['entry']} | {arms} | {pct} | {r['worst_arm']:.0f} | "
                     f"{r['median_ms']:.3g} | " + (f"{r['median_cpu_ms']:.3g} | " if cpu else "")
                     + f"{r['median_ratio']:.3g} |")
    return "\n".join(lines)


def fk_sentence(folder: str | Path, timeout_ms: float = 500.0) -> str:
    """The FK rows of a stored per-robot board at ``timeout_ms`` as README's one sentence: per
    parallel mechanism, each solver's success at the generating pose (the board's rung) and, in
    brackets, the share solved in another assembly mode; best first."""
    board = pd.read_csv(Path(folder) / "leaderboard-robots.csv")
    board = board[board["other_mode"].notna() & np.isclose(board["timeout_ms"], timeout_ms)]
    parts = []
    for robot, rows in board.groupby("robot", sort=False):
        rung = f"success_{rows['rung'].iloc[0]}"
        rows = rows.sort_values(rung, ascending=False, kind="stable")
        cells = [f"`{r['solver']}` {100 * r[rung]:.0f} % (+{100 * r['other_mode']:.0f} % another mode)"
                 for _, r in rows.iterrows()]
        parts.append(f"FK of {robot} at {timeout_ms:g} ms, at the generating pose: " + ", ".join(cells))
    return "; ".join(parts) + "."
