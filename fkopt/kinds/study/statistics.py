"""Statistics of a study over all (pose, run) pairs: ECDF of evaluations to target, pairwise
Wilcoxon rank-sum (Mann-Whitney U) tests with Holm's correction.

* ECDF (COCO style, Hansen et al., "COCO: performance assessment"): for each algorithm the
  fraction of all (pose, run) pairs that reached the threshold within b evaluations, as a step
  function of the budget b; pairs that never reached it keep the curve below 1.
* Pairwise tests: for every pair of algorithms and each metric -- final fitness, and
  evaluations to the threshold (a pair that never reached it counts as +inf, i.e. worse than
  any pair that did, and all such pairs tie) -- a two-sided Mann-Whitney U test
  (``scipy.stats.mannwhitneyu``, its default method) on the pooled (pose, run) samples. The
  p-values of one metric form one family, adjusted with Holm's step-down method. Lower is
  better for both metrics; ``prob_a_lower`` = P(a < b) + P(a = b) / 2 estimated from U (the
  Vargha-Delaney effect size of b over a). The samples are paired by pose, so a signed-rank
  test would be more powerful; the rank-sum test is what was asked for and does not assume
  pairing.
"""
from __future__ import annotations

from itertools import combinations

import numpy as np
import pandas as pd

METRICS = ("final_fitness", "evaluations_to_threshold")


def holm(pvalues) -> np.ndarray:
    """Holm's step-down adjusted p-values (same order as given), capped at 1 and monotone.

    Sorted ascending p_(1) <= ... <= p_(m): adj_(i) = max_{j <= i} min(1, (m - j + 1) p_(j)).
    """
    p = np.asarray(pvalues, dtype=float)
    m = p.size
    adj = np.empty(m)
    running = 0.0
    for rank, i in enumerate(np.argsort(p, kind="stable")):
        running = max(running, min(1.0, (m - rank) * p[i]))
        adj[i] = running
    return adj


def ecdf_table(samples: dict[str, np.ndarray]) -> pd.DataFrame:
    """Step points of the ECDF per algorithm: fraction of pairs solved within ``evaluations``.

    ``samples`` maps an algorithm to its evaluations-to-target over all pairs (NaN: unsolved).
    One row per distinct budget at which the fraction increases (plus a row at the first
    budget); an algorithm that solved nothing gets a single row with NaN evaluations.
    """
    rows = []
    for algo, ev in samples.items():
        ev = np.asarray(ev, dtype=float).ravel()
        n = ev.size
        solved = np.sort(ev[~np.isnan(ev)])
        if solved.size == 0:
            rows.append({"algorithm": algo, "evaluations": np.nan, "solved": 0, "pairs": n, "fraction": 0.0})
            continue
        values, counts = np.unique(solved, return_counts=True)
        cum = np.cumsum(counts)
        for v, c in zip(values, cum):
            rows.append({"algorithm": algo, "evaluations": float(v), "solved": int(c), "pairs": n,
                         "fraction": c / n})
    return pd.DataFrame(rows, columns=["algorithm", "evaluations", "solved", "pairs", "fraction"])


def pairwise_tests(samples: dict[str, dict[str, np.ndarray]], alpha: float = 0.05) -> pd.DataFrame:
    """Mann-Whitney U for every pair of algorithms and metric, Holm-adjusted per metric.

    ``samples[metric][algorithm]`` is the pooled sample (evaluations-to-target NaN = unsolved).
    """
    from scipy.stats import mannwhitneyu

    cols = ["metric", "algorithm_a", "algorithm_b", "n_a", "n_b", "median_a", "median_b", "U",
            "p_value", "p_holm", "significant", "better", "prob_a_lower"]
    frames = []
    for metric, by_algo in samples.items():
        rows = []
        for a, b in combinations(by_algo, 2):
            xa = np.asarray(by_algo[a], dtype=float).ravel()
            xb = np.asarray(by_algo[b], dtype=float).ravel()
            if metric == "evaluations_to_threshold":
                xa, xb = np.where(np.isnan(xa), np.inf, xa), np.where(np.isnan(xb), np.inf, xb)
            if np.all(xa == xa[0]) and np.all(xb == xa[0]):
                u, p = xa.size * xb.size / 2.0, 1.0      # every value tied: no evidence either way
            else:
                res = mannwhitneyu(xa, xb, alternative="two-sided")
                u, p = float(res.statistic), float(res.pvalue)
            rows.append({"metric": metric, "algorithm_a": a, "algorithm_b": b, "n_a": xa.size, "n_b": xb.size,
                         "median_a": float(np.median(xa)), "median_b": float(np.median(xb)), "U": u,
                         "p_value": p, "prob_a_lower": 1.0 - u / (xa.size * xb.size)})
        if not rows:
            continue
        df = pd.DataFrame(rows)
        df["p_holm"] = holm(df["p_value"].to_numpy())
        df["significant"] = df["p_holm"] < alpha
        df["better"] = [(r.algorithm_a if r.prob_a_lower > 0.5 else r.algorithm_b) if r.significant else ""
                        for r in df.itertuples()]
        frames.append(df)
    if not frames:
        return pd.DataFrame(columns=cols)
    return pd.concat(frames, ignore_index=True)[cols]
