"""The measures of a suite, as COCO defines them (Hansen et al., "COCO: Performance assessment",
2016/2022), from the per-run table of :mod:`fkopt.kinbench.runner` -- the one place they are
computed (tables, figures, markdown and HTML all read these functions' tables).

A *trial* is one run on one (problem, set, pose) *instance*; a *triple* is (instance, target).

* **success rate** of a solver at target t: the share of its trials whose best-so-far fitness
  went below t within the budget;
* **ERT** (expected running time) at t: total evaluations of all trials -- until t was reached,
  or the evaluations used within the budget when it was not -- divided by the number of
  successes (inf when there are none); also given per dimension;
* **ECDF** (empirical runtime distribution): the share of (triple, run) pairs reached within
  b x dimension evaluations, as a step function of b (one row per step), per solver over all
  problems and per problem class;
* **score** of a solver on an instance: the area under that instance's ECDF on the log axis of
  evaluations/dimension from 1 to the budget per dimension, normalised to [0, 1] -- the mean
  over its runs and targets of ``log(Bd / max(e/d, 1)) / log(Bd)`` for a target reached with e
  evaluations (0 when not reached). 1 would be every target at once; it rewards reaching more
  targets and reaching them sooner, as the area under COCO's ECDF does;
* **ranking** within a scope (all solvers; one track; one problem class within one track):
  solvers by mean score over the scope's instances; the 95 % confidence interval is the
  percentile interval of the mean over ``bootstrap`` resamples of the instances (with
  replacement; one resample shared by all solvers); solver a is *significantly better* than b
  when the two-sided Wilcoxon signed-rank test on the per-instance differences of their scores
  (paired by instance) rejects equality at ``alpha`` after Holm's correction over all pairs of
  the scope (:func:`fkopt.kinds.study.statistics.holm`), and a's mean score is higher. (A bootstrap
  p-value cannot go below 2 / (B + 1), which Holm's correction over the 45 pairs of ten solvers
  would never let pass at B = 1000: the signed-rank test has no such floor.)
"""
from __future__ import annotations

import zlib
from itertools import combinations

import numpy as np
import pandas as pd

from fkopt.kinds.study.statistics import ecdf_table as ecdf_steps
from fkopt.kinds.study.statistics import holm
from fkopt.kinbench.budget import target_column
from fkopt.errors import FkoptError

INSTANCE = ["problem", "set", "pose"]


#: One cell of a suite: a trial (one run on one instance).
CELL = INSTANCE + ["run"]


def board_runs(runs: pd.DataFrame, defining) -> pd.DataFrame:
    """The rows of a board: the cells (problem, set, pose, run) that the ``defining`` solvers
    ran, and of those only the solvers that ran every one of them -- so no solver on a board
    is judged on cells the others did not run, nor left out of cells it did not run (a solver
    missing a single cell is not on the board). Empty when the defining solvers ran nothing."""
    keys = runs.loc[runs["solver"].isin(list(defining)), CELL].drop_duplicates()
    if keys.empty:
        return runs.iloc[:0]
    inside = runs[CELL].merge(keys.assign(_in=True), on=CELL, how="left")["_in"].notna().to_numpy()
    sub = runs[inside]
    count = sub.groupby("solver", sort=False).size()
    return sub[sub["solver"].isin(count.index[count == len(keys)])]


def boards(runs: pd.DataFrame, cells) -> list[tuple[str, pd.DataFrame]]:
    """(board name, its rows by :func:`board_runs`) for each (name, defining solvers) of
    ``cells`` (:meth:`fkopt.kinbench.config.SuiteConfig.board_cells`) that holds any row."""
    out = [(name, board_runs(runs, defining)) for name, defining in cells]
    return [(name, sub) for name, sub in out if not sub.empty]


def ert_ratio_table(runs: pd.DataFrame, targets) -> pd.DataFrame:
    """ERT of each solver over the virtual best solver's, per (problem, track, target), COCO's
    ERT ratio (Hansen et al. 2022, sec. 5; the virtual best solver's ERT is the smallest of any
    solver of the track on that problem and target): 1 for the best, inf for a solver that
    never reached the target when another did, NaN when no solver of the track reached it.
    Over all sets and poses of the problem that ``runs`` holds (one board's cells)."""
    ert = _ert_rows(runs, ["problem", "class", "track", "solver"], targets, sort=False)
    finite = ert["ert"].where(np.isfinite(ert["ert"]))
    ert["ert_best"] = finite.groupby([ert["problem"], ert["track"], ert["target"]]).transform("min")
    ert["ert_ratio"] = ert["ert"] / ert["ert_best"]
    return ert[["problem", "class", "track", "solver", "target", "trials", "success_rate", "ert", "ert_best",
                "ert_ratio"]]


def ert_ratio_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per (class, track, solver, target): the median ERT ratio over the problems of the class
    whose target some solver of the track reached (what the board shows; ert_ratio.csv has
    every problem)."""
    t = table[table["ert_best"].notna()]
    return (t.groupby(["class", "track", "solver", "target"], sort=False)
            .agg(problems=("problem", "nunique"), median_ert_ratio=("ert_ratio", "median")).reset_index())


def hits(runs: pd.DataFrame, targets) -> np.ndarray:
    """(rows, targets) evaluations when each target was reached (NaN: not within budget)."""
    return runs[[target_column(t) for t in targets]].to_numpy(dtype=float)


def _ert_rows(runs: pd.DataFrame, keys: list[str], targets, sort: bool) -> pd.DataFrame:
    """Success rate and ERT per group of ``keys`` and target (one group has one dimension)."""
    rows = []
    for key, g in runs.groupby(keys, sort=sort):
        ev = hits(g, targets)
        used = g["evaluations"].to_numpy(dtype=float)
        dim = int(g["dim"].iloc[0])
        for j, t in enumerate(targets):
            ok = ~np.isnan(ev[:, j])
            n_ok = int(ok.sum())
            total = float(np.where(ok, ev[:, j], used).sum())
            ert = total / n_ok if n_ok else np.inf
            rows.append({**dict(zip(keys, key)), "target": t, "trials": len(g), "successes": n_ok,
                         "success_rate": n_ok / len(g), "ert": ert, "ert_per_dim": ert / dim})
    return pd.DataFrame(rows)


def measures_table(runs: pd.DataFrame, targets) -> pd.DataFrame:
    """Success rate and ERT per (problem, set, solver, target): the per-problem table."""
    return _ert_rows(runs, ["problem", "class", "set", "solver", "track"], targets, sort=False)


def scaling_table(runs: pd.DataFrame, targets) -> pd.DataFrame | None:
    """Success rate and ERT per (class, solver, dimension, target) over every problem, set and pose
    of that dimension, for the classes whose problems differ in dimension (kinbench v3's dh-chain
    family, n = 3 ... 30): how a solver's cost grows with the number of unknowns, COCO's scaling
    plot (ERT / dimension against dimension). None when no class has two dimensions."""
    multi = sorted(c for c, g in runs.groupby("class") if g["dim"].nunique() > 1)
    if not multi:
        return None
    return _ert_rows(runs[runs["class"].isin(multi)], ["class", "solver", "track", "dim"], targets, sort=True)


def ecdf_table(runs: pd.DataFrame, targets, budget_per_dim: float) -> pd.DataFrame:
    """Share of (problem, set, pose, target, run) reached within b x dim evaluations, per scope
    (``all`` and ``class:<c>``) and solver: the steps of the runtime distribution
    (:func:`fkopt.kinds.study.statistics.ecdf_table`, in evaluations / dimension)."""
    frames = []
    scopes = [("all", runs)] + [(f"class:{c}", g) for c, g in runs.groupby("class", sort=True)]
    for scope, sub in scopes:
        per_dim = hits(sub, targets) / sub["dim"].to_numpy(dtype=float)[:, None]
        solvers = list(dict.fromkeys(sub["solver"]))
        df = ecdf_steps({s: per_dim[(sub["solver"] == s).to_numpy()] for s in solvers})
        df = df.rename(columns={"algorithm": "solver", "evaluations": "evals_per_dim", "solved": "reached"})
        df.insert(0, "scope", scope)
        df.insert(2, "track", df["solver"].map(dict(zip(sub["solver"], sub["track"]))))
        frames.append(df)
    return pd.concat(frames, ignore_index=True)


def virtual_best_ecdf(runs: pd.DataFrame, targets) -> pd.DataFrame:
    """The ECDF of the virtual best solver over ``runs`` (one board's, or one class of it): per
    cell (problem, set, pose, run) and target the fewest evaluations / dimension any solver
    needed, as steps (evals_per_dim, fraction) of the same (cell, target) pairs as each solver's
    ECDF (COCO's "best 2009"-style reference curve, from the solvers run here)."""
    per_dim = pd.DataFrame(hits(runs, targets) / runs["dim"].to_numpy(dtype=float)[:, None], index=runs.index)
    best = per_dim.groupby([runs[c] for c in CELL], sort=False).min().to_numpy()
    steps = ecdf_steps({"virtual best": best})
    return steps.rename(columns={"evaluations": "evals_per_dim"})[["evals_per_dim", "fraction"]]


def trial_scores(runs: pd.DataFrame, targets, budget_per_dim: float) -> np.ndarray:
    """(rows,) the normalised log-area score of every trial (see the module docstring)."""
    per_dim = hits(runs, targets) / runs["dim"].to_numpy(dtype=float)[:, None]
    if budget_per_dim <= 1:
        return (~np.isnan(per_dim)).mean(axis=1)
    top = np.log(budget_per_dim)
    s = np.clip((top - np.log(np.maximum(np.nan_to_num(per_dim, nan=budget_per_dim), 1.0))) / top, 0, 1)
    return np.where(np.isnan(per_dim), 0.0, s).mean(axis=1)


def instance_scores(runs: pd.DataFrame, targets, budget_per_dim: float) -> pd.DataFrame:
    """(instances x solvers) mean trial score; an instance a solver did not run is NaN."""
    df = runs[INSTANCE + ["solver"]].copy()
    df["score"] = trial_scores(runs, targets, budget_per_dim)
    order = list(dict.fromkeys(runs["solver"]))
    return df.groupby(INSTANCE + ["solver"], sort=True)["score"].mean().unstack("solver")[order]


def rank_scope(scores: pd.DataFrame, bootstrap: int, alpha: float, seed: int, scope: str) -> pd.DataFrame:
    """Ranking of the columns of ``scores`` (instances x solvers; rows with a NaN dropped)."""
    s = scores.dropna(axis=0, how="any")
    solvers = list(s.columns)
    S = s.to_numpy(dtype=float)
    n = len(S)
    rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([int(seed), zlib.crc32(scope.encode())])))
    idx = np.floor(rng.random((bootstrap, n)) * n).astype(np.intp)
    boot = S[idx].mean(axis=1)                      # (B, solvers)
    mean = S.mean(axis=0)
    lo, hi = np.quantile(boot, [0.025, 0.975], axis=0)
    pairs = list(combinations(range(len(solvers)), 2))
    pvals = []
    from scipy.stats import wilcoxon
    for a, b in pairs:
        d = S[:, a] - S[:, b]
        pvals.append(1.0 if not np.any(d) else float(wilcoxon(d, zero_method="zsplit").pvalue))
    adj = holm(pvals) if pairs else np.array([])
    better = {k: [] for k in range(len(solvers))}
    for (a, b), p in zip(pairs, adj):
        if p < alpha and mean[a] != mean[b]:
            win, lose = (a, b) if mean[a] > mean[b] else (b, a)
            better[win].append(solvers[lose])
    rank = pd.Series(-np.round(mean, 12)).rank(method="min").astype(int).to_numpy()
    out = pd.DataFrame({"scope": scope, "solver": solvers, "instances": n, "score": mean,
                        "ci_low": lo, "ci_high": hi, "rank": rank,
                        "better_than": [";".join(sorted(better[k])) for k in range(len(solvers))]})
    return out.sort_values(["rank", "solver"], kind="stable").reset_index(drop=True)


def leaderboard_table(runs: pd.DataFrame, targets, budget_per_dim: float, *, bootstrap: int = 1000,
                      alpha: float = 0.05, seed: int = 0) -> pd.DataFrame:
    """Rankings of every scope: ``overall`` (all solvers, tracks mixed, for reference),
    ``track:<t>`` and ``class:<c>/track:<t>``; with each solver's success rate per target and
    ERT at the smallest target reached by anyone, over the scope."""
    tracks = dict(zip(runs["solver"], runs["track"]))
    scopes = [("overall", runs)]
    scopes += [(f"track:{t}", g) for t, g in runs.groupby("track", sort=True)]
    scopes += [(f"class:{c}/track:{t}", g) for (c, t), g in runs.groupby(["class", "track"], sort=True)]
    frames = []
    for scope, sub in scopes:
        ranked = rank_scope(instance_scores(sub, targets, budget_per_dim), bootstrap, alpha, seed, scope)
        ranked.insert(2, "track", ranked["solver"].map(tracks))
        ev = hits(sub, targets)
        for j, t in enumerate(targets):
            rate = pd.Series(~np.isnan(ev[:, j])).groupby(sub["solver"].to_numpy()).mean()
            ranked[f"success_{t:.0e}"] = ranked["solver"].map(rate)
        frames.append(ranked)
    return pd.concat(frames, ignore_index=True)


# -- nearness to a singularity, unit-free -------------------------------------------------------
# The condition number of a Jacobian mixing mm and degrees (v1/v2's near-singular sets) changes
# with the choice of units. kinbench v3 measures a pose's nearness to a singularity by the
# smallest singular value of the Jacobian made unit-free: angles in radians and lengths divided
# by a characteristic length L of the mechanism (Angeles, "Fundamentals of Robotic Mechanical
# Systems", 4th ed., sec. 5.8 -- the characteristic length that makes a Jacobian dimensionally
# homogeneous). sigma_min = 0 at a singularity; a value of s means a unit-free joint (or leg)
# motion of 1 moves the tool (or platform) by no more than s in some direction.
#
# * serial arm: J = the geometric frame Jacobian (position rows, angular-velocity rows) of
#   :meth:`FrameArm.frame_jacobian`; scaled J~ = diag(1/L, 1/L, 1/L, 1, 1, 1) J diag(c_j), c_j =
#   180/pi for a joint in degrees (per radian), L for a joint in a length unit. The IK of the
#   pose is ill-posed where J~ loses rank (of a redundant arm: the 6th singular value; of an arm
#   with n < 6 joints: the n-th). L = the largest distance of the tool point from the base origin
#   over the configurations measured (the pose set's candidates): the arm's reach.
# * parallel mechanism: J = d ik / d pose (joints per pose coordinate, central differences of the
#   closed-form inverse map); J~ = diag(r_i) J diag(c_j), r_i = 1/L for a length joint and pi/180
#   for a joint in degrees, c_j = L for a length coordinate and 180/pi for an angle. FK is
#   ill-posed where J~ loses rank (a direct-kinematics singularity, Gosselin & Angeles 1990,
#   "Singularity analysis of closed-loop kinematic chains"). L = the mean absolute value of the
#   length-unit joints at the centre of the workspace box (leg lengths / slider positions at home).
LENGTH_UNITS = ("mm", "m")


def _unit_factors(units, length: float, inverse: bool) -> np.ndarray:
    """Per coordinate: the factor from public units to unit-free ones (deg -> rad, length -> /L), or
    (``inverse``) the factor per unit-free unit (rad -> 180/pi deg, /L -> L)."""
    out = []
    for u in units:
        f = np.pi / 180.0 if u == "deg" else 1.0 / length if u in LENGTH_UNITS else 1.0
        out.append(1.0 / f if inverse else f)
    return np.array(out)


def characteristic_length(mech, points: np.ndarray) -> float:
    """L of the module's note above: a serial arm's largest tool distance over ``points`` (joint
    configurations), a parallel mechanism's mean absolute length-unit joint at the box centre."""
    if mech.kind == "serial":
        p, _, _ = mech.frame_jacobian(points)
        length = float(np.linalg.norm(p, axis=-1).max())
    else:
        centre = mech.bounds.mean(axis=1)
        legs = np.asarray(mech.ik(centre), dtype=float)
        lengths = [abs(v) for v, u in zip(legs, mech.joint_units) if u in LENGTH_UNITS]
        length = float(np.mean(lengths)) if lengths else 1.0
    return length if np.isfinite(length) and length > 0 else 1.0


def unit_free_jacobian(mech, points: np.ndarray, length: float) -> np.ndarray:
    """(k, rows, cols) the Jacobian J~ of the note above at each of ``points`` (k, unknowns)."""
    points = np.asarray(points, dtype=float)
    if mech.kind == "serial":
        if not hasattr(mech, "frame_jacobian"):
            raise FkoptError(f"{mech.name}: the unit-free singularity measure needs a frame Jacobian "
                             "(a frame arm: DH, URDF, MJCF)")
        _, _, J = mech.frame_jacobian(points)
        rows = np.array([1.0 / length] * 3 + [1.0] * 3)
        cols = _unit_factors(mech.joint_units, length, inverse=True)
        return rows[:, None] * J * cols[None, :]
    h = 1e-6 * np.maximum(1.0, np.abs(points))
    cols = []
    for j in range(points.shape[1]):
        e = np.zeros_like(points)
        e[:, j] = h[:, j]
        cols.append((np.asarray(mech.ik(points + e)) - np.asarray(mech.ik(points - e))) / (2 * h[:, j, None]))
    J = np.stack(cols, axis=-1)
    rows = _unit_factors(mech.joint_units, length, inverse=False)
    colf = _unit_factors(mech.pose_units, length, inverse=True)
    return rows[:, None] * J * colf[None, :]


def unit_free_sigma_min(mech, points: np.ndarray, length: float) -> np.ndarray:
    """(k,) the smallest singular value of J~ (0 at a singularity; NaN where J~ is not finite)."""
    J = unit_free_jacobian(mech, points, length)
    ok = np.all(np.isfinite(J), axis=(1, 2))
    out = np.full(len(J), np.nan)
    if ok.any():
        out[ok] = np.linalg.svd(J[ok], compute_uv=False)[:, -1]
    return out
