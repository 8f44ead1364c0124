"""studies: fkopt's own workspace studies (not a paper): many poses, statistics, tracking.

Configs ``configs/studies/*.yaml`` (``kind: study``, see :mod:`fkopt.kinds.study`). The "claims"
below are findings of fkopt's runs, each judged against an expectation stated in advance
(in the claim's text), from the seed-determined tables only; timing findings are in
:func:`timing_claims`.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from fkopt.reproduce.claims import Claim, g, missing, verdict

TITLE = ("fkopt workspace studies: success rates, evaluations-to-target ECDFs and Wilcoxon-Holm "
         "tests over many poses, a 2-D slice heat map, and trajectory tracking with warm starts")

EXPERIMENTS = ["3rps_workspace", "3rps_slice", "6sps_tracking"]

NOTES = [
    "Not a paper: fkopt's own studies of the papers' mechanisms over their workspaces "
    "(`kind: study` configs in `configs/studies/`, run with `fkopt study`). Each row of a summary "
    "pools all (pose, run) pairs of an algorithm; success = final fitness below the threshold; "
    "iterations/evaluations to the threshold are medians over the pairs that reached it.",
    "Every run stops at the threshold (`stop_at_threshold`), so evaluations-to-target measure the "
    "cost and the final fitness is the fitness at the stop (for the swarms just below the "
    "threshold; for LM/NR often far below, because one Newton-type step overshoots it).",
    "Statistics: pairwise two-sided Wilcoxon rank-sum (Mann-Whitney U) tests on the pooled "
    "(pose, run) samples, Holm-corrected per metric at alpha = 0.05; a pair that never reached "
    "the threshold counts as +inf evaluations. The samples are paired by pose; the rank-sum test "
    "ignores that pairing (conservative). ECDFs follow COCO: fraction of (pose, run) pairs "
    "solved vs evaluations, log axis.",
    "Reduced sizes to keep `make reproduce` short: 50 uniform poses x 5 runs (the issue's example "
    "was 200 x 30), a 9 x 9 grid x 3 runs, two 40-step trajectories (a circle, a tilting line) x 3 runs, solved together step by step. Larger studies: "
    "`fkopt study CONFIG --jobs N` or `--executor dask --scheduler ADDRESS`; results are identical "
    "whatever the executor.",
    "LM/NR 'from the centre' start at the centre of the search box, the same point for every pose "
    "(a controller without prior knowledge); their runs are identical (deterministic).",
    "6-SPS CMM: the workspace box (x, y in [-0.2, 0.2] m, z in [0.7, 1.1] m, angles in "
    "[-30, 30] deg) is fkopt's choice (liu2008 prints none). Tracking: LM starts each step at the "
    "previous step's solution of the same run; PSO+LM searches a box of +-5 % of the workspace "
    "width around it; `lm-cold` starts every step at the centre.",
]


def _summary(exp) -> pd.DataFrame:
    return exp.table("summary").set_index("algorithm")


def _stat(exp, metric: str, a: str, b: str):
    st = exp.table("stats")
    hit = st[(st.metric == metric) & (((st.algorithm_a == a) & (st.algorithm_b == b))
                                     | ((st.algorithm_a == b) & (st.algorithm_b == a)))]
    return hit.iloc[0] if len(hit) else None


def _better(row) -> str:
    return "" if row is None or not isinstance(row.better, str) else row.better


def _stat_text(row) -> str:
    if row is None:
        return "no test"
    return (f"medians {row.algorithm_a} {g(row.median_a)} vs {row.algorithm_b} {g(row.median_b)}, "
            f"Holm-adjusted p = {g(row.p_holm)}")


def claims(store) -> list[Claim]:
    out: list[Claim] = []
    ws = store.get("studies", "3rps_workspace")
    if ws is None:
        out.append(missing("3-RPS workspace findings", "studies/3rps_workspace"))
    else:
        s = _summary(ws)
        poses = ws.table("poses")
        lm = poses[poses.algorithm == "lm"]
        out.append(Claim(
            "Expectation: LM from the workspace centre solves at least 95 % of uniform 3-RPS workspace "
            "poses to fitness < 1e-10 (the forward map is smooth over alpha, beta in +-20 deg)",
            verdict(s.loc["lm", "success_rate"] >= 0.95),
            f"LM succeeds on {g(100 * s.loc['lm', 'success_rate'])} % of (pose, run) pairs and on "
            f"{g(100 * float((lm.success_rate == 1).mean()))} % of the {len(lm)} poses, with a median "
            f"of {g(s.loc['lm', 'median_evaluations_to_threshold'])} residual evaluations"))
        swarms = [a for a in ("gabc", "abc") if a in s.index]
        out.append(Claim(
            "Expectation: with mao2017's budget (population 10, 600 iterations) GABC and ABC reach "
            "1e-10 on at least 95 % of the workspace poses, not only at the paper's pose",
            verdict(all(s.loc[a, "success_rate"] >= 0.95 for a in swarms)),
            ", ".join(f"{a.upper()} success {g(100 * s.loc[a, 'success_rate'])} %" for a in swarms)))
        row = _stat(ws, "evaluations_to_threshold", "gabc", "abc")
        out.append(Claim(
            "Expectation (mao2017's Fig. 2/3 claim carried over to the workspace): GABC needs "
            "significantly fewer evaluations to 1e-10 than ABC (rank-sum test, Holm, alpha 0.05)",
            verdict(_better(row) == "gabc"),
            _stat_text(row) + (f"; significantly fewer: {_better(row)}" if _better(row) else
                               "; no significant difference")))
        row = _stat(ws, "evaluations_to_threshold", "gabc", "gabc+lm")
        out.append(Claim(
            "Expectation: the GABC+LM hybrid needs significantly fewer evaluations to 1e-10 than GABC",
            verdict(_better(row) == "gabc+lm"), _stat_text(row)))
    sl = store.get("studies", "3rps_slice")
    if sl is None:
        out.append(missing("3-RPS slice findings", "studies/3rps_slice"))
    else:
        h = sl.table("heatmap")
        for algo in ("nr", "lm"):
            d = h[h.algorithm == algo]
            if d.empty:
                continue
            a, b = d.columns[0], d.columns[1]
            edge = max(d[a].abs().max(), d[b].abs().max())
            corner = d[(d[a].abs() == edge) & (d[b].abs() == edge)]
            out.append(Claim(
                f"Expectation: {algo.upper()} from the workspace centre succeeds at every point of the "
                f"alpha x beta slice, corners included",
                verdict(d.success_rate.min() == 1.0),
                f"lowest success rate over the {len(d)} grid points {g(d.success_rate.min())}; median "
                f"evaluations to 1e-10 at the 4 corners {g(corner.median_evaluations_to_threshold.median())} "
                f"vs {g(d.median_evaluations_to_threshold.median())} over the slice"))
    tr = store.get("studies", "6sps_tracking")
    if tr is None:
        out.append(missing("6-SPS tracking findings", "studies/6sps_tracking"))
    else:
        s = _summary(tr)
        out.append(Claim(
            "Expectation: warm-started LM tracks every step of both trajectories to fitness < 1e-14 m^2",
            verdict(s.loc["lm", "success_rate"] == 1.0),
            f"success {g(100 * s.loc['lm', 'success_rate'])} % of the (step, run) pairs; PSO+LM "
            f"{g(100 * s.loc['pso+lm', 'success_rate'])} %, cold LM {g(100 * s.loc['lm-cold', 'success_rate'])} %"))
        row = _stat(tr, "evaluations_to_threshold", "lm", "lm-cold")
        out.append(Claim(
            "Expectation: starting each step from the previous solution saves LM evaluations "
            "compared with starting from the workspace centre (rank-sum test, Holm)",
            verdict(_better(row) == "lm"), _stat_text(row)))
    return out


def timing_claims(store) -> list[Claim]:
    out = []
    tr = store.get("studies", "6sps_tracking")
    if tr is not None and tr.has("tracking_timing.csv"):
        t = tr.table("tracking_timing")
        med = t.groupby("algorithm")["ms_per_run"].median()
        out.append(Claim(
            "Expectation: a warm-started LM step of the 6-SPS CMM takes under 10 ms (a 100 Hz loop)",
            verdict(med.get("lm", np.inf) < 10.0),
            f"median ms per step: LM warm {g(med.get('lm'))}, LM cold {g(med.get('lm-cold'))}, "
            f"PSO+LM {g(med.get('pso+lm'))}"))
    return out


def extra_tables(exp) -> list[tuple[str, pd.DataFrame]]:
    """The Wilcoxon-Holm tests of every study, and the tracking summary per algorithm."""
    out = []
    if exp.has("stats.csv"):
        st = exp.table("stats")
        if not st.empty:
            st = st[["metric", "algorithm_a", "algorithm_b", "median_a", "median_b", "p_value", "p_holm",
                     "better"]].copy()
            st["better"] = st["better"].fillna("(none)")
            out.append(("Pairwise Wilcoxon rank-sum tests over all (pose, run) pairs (`stats.csv`, Holm-"
                        "adjusted per metric; `better` = significantly lower at alpha 0.05):", st))
    if exp.has("tracking.csv"):
        t = exp.table("tracking")
        errs = [c for c in t.columns if c.startswith("max_abs_error_")]
        agg = t.groupby("algorithm", sort=False).agg(
            steps=("step", "size"), warm_steps=("warm_start", "sum"), success_rate=("success_rate", "mean"),
            median_evaluations_per_step=("median_evaluations", "median"),
            **{f"max_{c.removeprefix('max_abs_error_')}_error": (c, "max") for c in errs}).reset_index()
        out.append(("Tracking per algorithm (`tracking.csv`): steps warm-started from the previous "
                    "solution, success rate, evaluations per step, largest error along the trajectories:", agg))
    return out
