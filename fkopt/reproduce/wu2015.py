"""wu2015: planar 3-PPR forward kinematics, improved ACO vs Newton-Raphson (docs/models.md "wu2015").

Claims, notes and inconsistencies are data (configs/wu2015/claims.yaml). With the reconstructed
geometry the inputs of every pose have two exact solutions in the workspace, the pose and its mirror
(x + r_F sin(theta), y, -theta); this module classifies each run by the solution it converged to
(:func:`branch_of_runs`), builds the tables, and measures the numbers the claims file names.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from fkopt import registry
from fkopt.problems import fk_problem
from fkopt.reproduce.claims import compare, g
from fkopt.reproduce.store import mechanism_of

EXAMPLE = {"x": 20.0, "y": 30.0, "theta": 15.0}
PRINTED_D = {"d1": -14.8355, "d2": 65.3984, "d3": 70.1170}
PRINTED_EXAMPLE = {"x": 20.0002, "y": 29.9993, "theta": 15.0001}
PRINTED_F = 2.25e-4          # printed as "f = -2.25e-4" (the pheromone tau = -f)
#: A run belongs to an exact solution when every coordinate is within this fraction of the box
#: width of it (0.12 mm in x, y; 0.048 deg in theta).
BRANCH_TOL = 1e-3


def _mechanism(exp=None):
    return mechanism_of(exp if exp is not None else "3-ppr")


def _fitness(mech, target, poses) -> np.ndarray:
    return fk_problem(mech, mech.ik(np.asarray(target, dtype=float))).fitness(np.asarray(poses, dtype=float))


def _targets(exp) -> dict[str, np.ndarray]:
    """Target pose (x, y, theta) per case label, from values.csv."""
    v = exp.table("values")
    v = v[v.algorithm == v.algorithm.iloc[0]]
    out = {}
    for case, grp in v.groupby("case", sort=False):
        t = grp.set_index("variable")["target"]
        out[case] = np.array([t["x"], t["y"], t["theta"]], dtype=float)
    return out


def _printed(exp) -> dict[str, dict]:
    """Per case label: the case's ``printed`` mapping from the recorded config."""
    out = {}
    for i, c in enumerate(exp.config["cases"]):
        out[c.get("label") or f"case-{i + 1}"] = c.get("printed") or {}
    return out


def branch_of_runs(exp) -> pd.DataFrame:
    """runs.csv plus, per run, the exact solution it converged to and its errors.

    ``branch``: ``target`` (the nominal pose), ``mirror`` (the other exact forward solution of the
    same inputs) or ``neither`` (farther than BRANCH_TOL of the box width from both);
    ``rel_error_<v>`` = |x_v - target_v| / |target_v| (Tab. 1's error measure).
    """
    mech = _mechanism(exp)
    width = mech.bounds[:, 1] - mech.bounds[:, 0]
    runs = exp.table("runs").copy()
    targets = _targets(exp)
    branch, mirror_cols = [], {"mirror_x": [], "mirror_y": [], "mirror_theta": []}
    x = runs[["x_x", "x_y", "x_theta"]].to_numpy(dtype=float)
    for k, case in enumerate(runs["case"]):
        target = targets[case]
        sols = mech.fk_exact(mech.ik(target))
        d_sol = np.max(np.abs(sols - target) / width, axis=-1)
        it = int(np.argmin(d_sol))
        mirror = sols[1 - it]
        d = np.max(np.abs(sols - x[k]) / width, axis=-1)
        near = int(np.argmin(d))
        branch.append("neither" if d[near] > BRANCH_TOL else ("target" if near == it else "mirror"))
        for j, n in enumerate(("x", "y", "theta")):
            mirror_cols[f"mirror_{n}"].append(float(mirror[j]))
    runs["branch"] = branch
    for k, v in mirror_cols.items():
        runs[k] = v
    tgt = np.array([targets[c] for c in runs["case"]])
    for j, n in enumerate(("x", "y", "theta")):
        runs[f"rel_error_{n}"] = np.abs(x[:, j] - tgt[:, j]) / np.abs(tgt[:, j])
    return runs


def branch_table(exp) -> pd.DataFrame:
    """Per case and algorithm: runs on the target solution, on its mirror, on neither."""
    runs = branch_of_runs(exp)
    mech = _mechanism(exp)
    rows = []
    for (case, algo), grp in runs.groupby(["case", "algorithm"], sort=False):
        r0 = grp.iloc[0]
        mirror = np.array([r0.mirror_x, r0.mirror_y, r0.mirror_theta])
        rows.append({"case": case, "algorithm": algo, "runs": len(grp),
                     "on_target": int((grp.branch == "target").sum()),
                     "on_mirror": int((grp.branch == "mirror").sum()),
                     "on_neither": int((grp.branch == "neither").sum()),
                     "mirror_solution": f"({mirror[0]:.4f}, {mirror[1]:.4f}, {mirror[2]:.4f})",
                     "mirror_in_workspace": bool(mech.in_bounds(mirror)),
                     "median_fitness": float(grp.final_fitness.median())})
    return pd.DataFrame(rows)


def tab1_table(exp) -> pd.DataFrame:
    """Per case and variable: printed value and error beside fkopt's runs on the target solution."""
    runs = branch_of_runs(exp)
    targets, printed = _targets(exp), _printed(exp)
    mech = _mechanism(exp)
    rows = []
    for case, grp in runs.groupby("case", sort=False):
        on = grp[grp.branch == "target"]
        p = printed.get(case, {}).get(grp.algorithm.iloc[0], {})
        target = targets[case]
        have = all(n in p for n in ("x", "y", "theta"))
        f_printed = float(_fitness(mech, target, [p["x"], p["y"], p["theta"]])) if have else np.nan
        for j, n in enumerate(("x", "y", "theta")):
            pv = p.get(n, np.nan)
            rows.append({"case": case, "variable": n, "target": target[j],
                         "printed_value": f"{pv:.4f}" if np.isfinite(pv) else "",
                         "printed_error_column": p.get(f"{n}_error", np.nan),
                         "printed_relative_error": abs(pv - target[j]) / abs(target[j]),
                         "fitness_of_printed_answer": f_printed,
                         "runs_on_target": len(on),
                         "fkopt_median_value": f"{on[f'x_{n}'].median():.4f}" if len(on) else "",
                         "fkopt_median_relative_error": float(on[f"rel_error_{n}"].median()) if len(on) else np.nan,
                         "fkopt_worst_relative_error": float(on[f"rel_error_{n}"].max()) if len(on) else np.nan})
    return pd.DataFrame(rows)


def newton_steps_table(exp, steps: int = 6) -> pd.DataFrame:
    """Fitness after k Newton steps per start (convergence.csv; one run per start)."""
    c = exp.table("convergence")
    c = c[c.iteration < steps]
    piv = c.pivot(index="iteration", columns="algorithm", values="median")
    piv = piv[[a for a in dict.fromkeys(c.algorithm)]]
    piv.columns = [f"fitness {a}" for a in piv.columns]
    return piv.reset_index().rename(columns={"iteration": "newton_step"})


def nr_printed_table(exp) -> pd.DataFrame:
    """Tab. 2's printed answers: their relative errors recomputed and their fitness (reconstruction)."""
    mech = _mechanism(exp)
    targets, printed = _targets(exp), _printed(exp)
    runs = exp.table("runs")
    rows = []
    order = [a.get("label") or a["name"] for a in exp.config["algorithms"]]
    for case, per_algo in printed.items():
        target = targets[case]
        for algo in sorted(per_algo, key=lambda a: order.index(a) if a in order else len(order)):
            p = per_algo[algo]
            pose = [p["x"], p["y"], p["theta"]]
            r = runs[(runs.case == case) & (runs.algorithm == algo)]
            row = {"start": algo, "printed_answer": f"({p['x']}, {p['y']}, {p['theta']})",
                   "fitness_of_printed_answer": float(_fitness(mech, target, pose))}
            for j, n in enumerate(("x", "y", "theta")):
                row[f"{n}_error_printed"] = p.get(f"{n}_error", np.nan)
                row[f"{n}_error_recomputed"] = abs(p[n] - target[j]) / abs(target[j])
            if len(r):
                row["fkopt_final_fitness"] = float(r.final_fitness.iloc[0])
                row["fkopt_max_abs_error"] = float(r[["abs_error_x", "abs_error_y", "abs_error_theta"]].max(axis=1).iloc[0])
            rows.append(row)
    return pd.DataFrame(rows)


def pheromone_table(exp) -> pd.DataFrame:
    """Final best and mean pheromone per case (median over runs) and the mean ant fitness."""
    runs = exp.table("runs")
    if "final_pheromone_mean" not in runs:
        return pd.DataFrame()
    rho = _rho(exp)
    rows = []
    for (case, algo), grp in runs.groupby(["case", "algorithm"], sort=False):
        rows.append({"case": case, "algorithm": algo,
                     "median_final_pheromone_best": float(grp.final_pheromone_best.median()),
                     "median_final_pheromone_mean": float(grp.final_pheromone_mean.median()),
                     "median_mean_ant_fitness": float((-(1 - rho) * grp.final_pheromone_mean).median())})
    return pd.DataFrame(rows)


def _rho(exp) -> float:
    for a in exp.config["algorithms"]:
        if a["name"] == "aco":
            return float((a.get("params") or {}).get("rho", registry.algorithm_class("aco").Params().rho))
    return float(registry.algorithm_class("aco").Params().rho)


def extra_tables(exp) -> list[tuple[str, pd.DataFrame]]:
    if exp.name == "tab1_fig4_7":
        return [
            ("Tab. 1 (and the worked example) beside fkopt: the printed 'absolute error' column (as printed) "
             "is |printed - target| / |target| (recomputed in `printed_relative_error`); fkopt's relative "
             "errors are over the runs that ended on the target solution; `fitness_of_printed_answer` "
             "under the reconstructed model:", tab1_table(exp)),
            (f"Which exact solution each run converged to (within {BRANCH_TOL:g} of the box width): the "
             "target pose or its mirror, which reproduces the same inputs:", branch_table(exp)),
            ("Fig. 7 in numbers: final best and mean pheromone (median over runs); in steady state "
             "tau = -f / (1 - rho), so the mean ant's fitness is -(1 - rho) x mean pheromone:",
             pheromone_table(exp)),
        ]
    if exp.name == "tab2_nr":
        return [
            ("Tab. 2: fitness after each Newton step from each start (fkopt's NR, one run per start); "
             "the four starts with theta = 10 deg coincide from the first step on:", newton_steps_table(exp)),
            ("Tab. 2's printed answers: errors as printed vs recomputed as relative errors, their "
             "fitness under the reconstructed model, and fkopt's final fitness and largest absolute "
             "error from the same start:", nr_printed_table(exp)),
        ]
    if exp.name == "baselines":
        return [("Which exact solution each run converged to (target pose or its mirror):", branch_table(exp))]
    return []


#: Sec. 5's printed fitness of the example's answer: a run "solves" the example at or below it.
SOLVED_F = PRINTED_F


def run_columns(exp, runs: pd.DataFrame) -> pd.DataFrame:
    """runs.csv plus ``on_target`` (1: the run solved the inputs, f <= 2.25e-4, on the paper's pose)
    and ``any_solution`` (1: it solved them on the pose or on its mirror, which reproduces the same
    inputs): the one rule for mirror outcomes counts a mirror run as solving the inputs only."""
    b = branch_of_runs(exp)
    solved = b.final_fitness.to_numpy(float) <= SOLVED_F
    return runs.assign(on_target=(solved & (b.branch == "target").to_numpy()).astype(float),
                       any_solution=(solved & (b.branch != "neither").to_numpy()).astype(float))


# -- the numbers claims.yaml names -------------------------------------------------------------
def _exp(store, name):
    return store.get("wu2015", name)


def example_inputs_difference_mm(store):
    mech = _mechanism()
    d = mech.ik(mech.vector(EXAMPLE, mech.pose_names, "example"))
    worst = float(np.abs(d - np.array(list(PRINTED_D.values()))).max())
    return worst, "fkopt's inverse map: " + ", ".join(f"{v:.4f}" for v in d) + " mm", {"max_difference_mm": worst}


def printed_answer_decades_from_printed_f(store):
    mech = _mechanism()
    f = float(_fitness(mech, mech.vector(EXAMPLE, mech.pose_names, "example"), list(PRINTED_EXAMPLE.values())))
    dec = abs(np.log10(PRINTED_F / f))
    return dec, f"fitness of the printed answer under the reconstructed model: {g(f)}", {"fitness": f}


def mirrors_in_workspace(store):
    t1 = _exp(store, "tab1_fig4_7")
    if t1 is None:
        return None
    bt = branch_table(t1)
    n, on = int(bt.mirror_in_workspace.sum()), int(bt.on_mirror.sum())
    return n, (f"the mirror solution lies in the workspace for {n} of {len(bt)} poses (e.g. "
               f"{bt.mirror_solution.iloc[0]} for the example); {on} of {int(bt.runs.sum())} ACO runs ended there "
               "with the inputs reproduced"), {"mirrors_in_workspace": n, "runs_on_mirror": on}


def tab1_worst_median_relative_error(store):
    t1 = _exp(store, "tab1_fig4_7")
    if t1 is None:
        return None
    tt = tab1_table(t1)
    tab1 = tt[tt.case != tt.case.iloc[0]]
    worst = float(tab1.fkopt_median_relative_error.max())
    return worst, (f"median relative error over the runs on the target solution, largest over the five poses and "
                   f"variables: {g(worst)}; runs on the target per pose "
                   f"{', '.join(str(int(x)) for x in tab1.groupby('case', sort=False).runs_on_target.first())}"), \
        {"worst_median_relative_error": worst}


def mean_ant_fitness(store):
    t1 = _exp(store, "tab1_fig4_7")
    if t1 is None or pheromone_table(t1).empty:
        return None
    v = float(pheromone_table(t1).iloc[0].median_mean_ant_fitness)
    return v, f"example after 1000 iterations: mean ant fitness (from the mean pheromone, median over runs) {g(v)}", \
        {"mean_ant_fitness": v}


def share_on_target(store):
    t1 = _exp(store, "tab1_fig4_7")
    if t1 is None:
        return None
    share = float((branch_of_runs(t1).branch == "target").mean())
    return share, f"share of ACO runs (all six poses) ending on the target solution: {g(share)}", \
        {"share_on_target": share}


def nr_largest_abs_error(store):
    t2 = _exp(store, "tab2_nr")
    if t2 is None:
        return None
    r = t2.table("runs")
    err = r[["abs_error_x", "abs_error_y", "abs_error_theta"]].max(axis=1)
    return float(err.max()), (f"fkopt's NR from the five printed starts: largest absolute error {g(err.max())}, "
                              f"final fitness {', '.join(g(x) for x in r.final_fitness)}"), {"max_abs_error": float(err.max())}


def nr_theta10_spread_decades(store):
    t2 = _exp(store, "tab2_nr")
    if t2 is None:
        return None
    steps = newton_steps_table(t2).set_index("newton_step")
    same = [c for c in steps.columns if c.split()[-1].split("/")[-1] == "10"]
    f = np.log10(steps.loc[1:3, same].to_numpy())
    spread = float(np.max(np.abs(f - f[:, :1])))
    return spread, (f"the fitness after Newton steps 1-3 of the four theta = 10 starts agrees to {spread:.1e} decades; "
                    "eq. (7) is linear in x, y, so an iterate depends only on the start's theta"), {"spread": spread}


def aco_minus_nr_median_relative_error(store):
    t1, t2 = _exp(store, "tab1_fig4_7"), _exp(store, "tab2_nr")
    if t1 is None or t2 is None:
        return None
    runs = branch_of_runs(t1)
    ex = runs[(runs["case"] == runs["case"].iloc[0]) & (runs.branch == "target")]
    aco = ex[["rel_error_x", "rel_error_y", "rel_error_theta"]].max(axis=1).to_numpy()
    r = t2.table("runs")
    nr = (r[["abs_error_x", "abs_error_y", "abs_error_theta"]].to_numpy() / np.array([20.0, 30.0, 15.0])).max(axis=1)
    c = compare("ACO", aco, "NR", nr)
    return c.median_a - c.median_b, (f"largest relative error per run on the example, over the {aco.size} ACO runs "
                                     f"that end on the target pose (the others end on its mirror): {c.text()}"), \
        {"p": c.p, "lower": c.lower, "median_aco": c.median_a, "median_nr": c.median_b}


#: The 3-PPR's topology as printed (Sec. 2): a base, a moving platform and three legs of two links each,
#: every leg prismatic (actuated) - prismatic - revolute; every joint a planar lower pair (1 DOF).
TOPOLOGY = {"links": 1 + 1 + 3 * 2, "joints": 3 * 3}


def gruebler_mobility(store):
    """Planar Gruebler-Kutzbach mobility M = 3 (n - 1) - 2 j of the printed topology (no geometry
    enters), with the rank of eq. (7)'s Jacobian at the example beside it (reconstructed geometry)."""
    n, j = TOPOLOGY["links"], TOPOLOGY["joints"]
    mobility = 3 * (n - 1) - 2 * j
    mech = _mechanism()
    rank = int(np.linalg.matrix_rank(mech.jacobian(mech.vector(EXAMPLE, mech.pose_names, "example"))))
    return float(mobility), (f"planar Gruebler-Kutzbach M = 3 (n - 1) - 2 j with n = {n} links and j = {j} one-DOF "
                             f"joints (three P-P-R legs); the Jacobian of eq. (7) at the example has rank {rank}"), \
        {"mobility": mobility, "jacobian_rank": rank}


QUANTITIES = {f.__name__: f for f in (gruebler_mobility, example_inputs_difference_mm, printed_answer_decades_from_printed_f,
                                      mirrors_in_workspace, tab1_worst_median_relative_error, mean_ant_fitness,
                                      share_on_target, nr_largest_abs_error, nr_theta10_spread_decades,
                                      aco_minus_nr_median_relative_error)}
