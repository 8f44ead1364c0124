"""wang7dof: 7-DOF redundant arm inverse kinematics, ABC vs PSO (docs/models.md "wang7dof").

Claims, notes and the paper's inconsistencies are data (configs/wang7dof/claims.yaml). This
module derives what is specific to an IK arm: every run's orientation errors (paper Euler norm,
each difference wrapped to +-180 deg, and geodesic) and whether it meets Sec. 3's requirement
(:func:`run_columns`), the forward kinematics of Tab. 2's printed joints, and the Tab. 2/3 tables.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from fkopt.kinds.experiment.config import ExperimentConfig
from fkopt.kinds.experiment.runner import build_cases, build_problem
from fkopt.reproduce.claims import g
from fkopt.run.solving import build_mechanism

#: Tab. 2's printed joint solutions (deg); the PSO column lost its decimal points ("48 282").
PRINTED_JOINTS = {"pso": (48.282, -6.758, 47.497, 34.208, 50.654, -60.107, -30.0),
                  "abc": (101.19, -9.52, -14.32, 4.36, 39.68, 35.94, 72.68)}
TARGET_JOINTS = (45.0, 0.0, 45.0, 0.0, 45.0, 0.0, 0.0)
#: Sec. 3: position error <= 0.1 mm, orientation error <= 1e-3 (unit garbled as "mm"; read as rad).
POSITION_REQUIREMENT_MM = 0.1
ORIENTATION_REQUIREMENT_DEG = float(np.degrees(1e-3))


def _problems(exp):
    """(mechanism, {case label: IK problem}) rebuilt from the experiment's recorded config."""
    cfg = ExperimentConfig(**exp.config)
    mech = build_mechanism(cfg)
    return mech, {c.label: build_problem(cfg, mech, c) for c in build_cases(cfg, mech)}


def errors_of(problem, joints) -> dict[str, np.ndarray]:
    """Position error (mm), paper (Euler) and geodesic orientation errors (deg) of joint vectors."""
    q = np.atleast_2d(np.asarray(joints, dtype=float))
    return {"position_error_mm": problem.position_error(q), "euler_error_deg": problem.rotation_error(q, "paper"),
            "geodesic_error_deg": problem.rotation_error(q, "geodesic")}


def run_columns(exp, runs: pd.DataFrame) -> pd.DataFrame:
    """runs.csv plus every run's orientation errors and ``meets_requirement`` (Sec. 3)."""
    mech, problems = _problems(exp)
    runs = runs.copy()
    cols = [f"x_{n}" for n in mech.joint_names]
    for label, pr in problems.items():
        mask = (runs["case"] == label).to_numpy()
        for k, v in errors_of(pr, runs.loc[mask, cols].to_numpy()).items():
            runs.loc[mask, k] = v
    runs["meets_requirement"] = ((runs.position_error_mm <= POSITION_REQUIREMENT_MM)
                                 & (runs.euler_error_deg <= ORIENTATION_REQUIREMENT_DEG)).astype(float)
    return runs


def printed_solutions_table(exp) -> pd.DataFrame:
    """fk of Tab. 2's printed joint vectors and their errors against the target."""
    mech, problems = _problems(exp)
    pr = next(iter(problems.values()))
    rows = []
    for algo, q in PRINTED_JOINTS.items():
        pose = mech.fk(np.array([q]))[0]
        rows.append({"printed_solution": algo, **dict(zip(mech.joint_names, q)),
                     **{f"fk_{n}": v for n, v in zip(mech.pose_names, pose)},
                     **{k: float(v[0]) for k, v in errors_of(pr, q).items()}})
    return pd.DataFrame(rows)


def printed_solutions_position_error_mm(store):
    exp = store.get("wang7dof", "tab2_tab3_fig5_fig6")
    if exp is None:
        return None
    p = printed_solutions_table(exp).set_index("printed_solution")
    worst = float(p.position_error_mm.max())
    return worst, (f"fk of the printed joints: ABC {g(p.loc['abc', 'position_error_mm'])} mm and "
                   f"{g(p.loc['abc', 'geodesic_error_deg'])} deg, PSO {g(p.loc['pso', 'position_error_mm'])} mm "
                   f"and {g(p.loc['pso', 'geodesic_error_deg'])} deg from the target"), \
        {"position_error_abc": float(p.loc["abc", "position_error_mm"]),
         "position_error_pso": float(p.loc["pso", "position_error_mm"])}


QUANTITIES = {"printed_solutions_position_error_mm": printed_solutions_position_error_mm}


def table2(exp) -> pd.DataFrame:
    """Tab. 2: joint solution of the median run of each algorithm beside the printed ones."""
    mech, _ = _problems(exp)
    runs = run_columns(exp, exp.table("runs"))
    printed = printed_solutions_table(exp).set_index("printed_solution")
    errs = ("position_error_mm", "euler_error_deg", "geodesic_error_deg")
    rows = [{"solution": "target", **dict(zip(mech.joint_names, TARGET_JOINTS)), **{k: 0.0 for k in errs}}]
    for algo, grp in runs.groupby("algorithm", sort=False):
        m = grp.sort_values("final_fitness", kind="stable").iloc[(len(grp) - 1) // 2]
        rows.append({"solution": f"fkopt {algo} (median run {int(m.run)})",
                     **{n: m[f"x_{n}"] for n in mech.joint_names}, **{k: m[k] for k in errs}})
        if algo in printed.index:
            rows.append({"solution": f"printed {algo}", **{n: printed.loc[algo, n] for n in mech.joint_names},
                         **{k: printed.loc[algo, k] for k in errs}})
    return pd.DataFrame(rows)


def table3(exp) -> pd.DataFrame:
    """Tab. 3 (deterministic part): iterations to best and position error over all runs."""
    runs = run_columns(exp, exp.table("runs"))
    conv, s = exp.table("convergence"), exp.table("summary").set_index("algorithm")
    rows = []
    for algo, grp in runs.groupby("algorithm", sort=False):
        c = conv[conv.algorithm == algo].groupby("iteration")["median"].median().to_numpy()
        rows.append({
            "algorithm": algo, "runs": len(grp), "median_iterations_to_best": grp.iterations_to_best.median(),
            "median_curve_within_1pct_at": int(np.argmax(c <= c[-1] * 1.01)),
            "median_position_error_mm": grp.position_error_mm.median(),
            "mean_position_error_mm": grp.position_error_mm.mean(),
            "median_euler_error_deg": grp.euler_error_deg.median(),
            "median_geodesic_error_deg": grp.geodesic_error_deg.median(),
            "median_fitness": grp.final_fitness.median(), "share_meeting_requirement": grp.meets_requirement.mean(),
            "printed_iterations_to_best": s.loc[algo].get("printed_iterations_to_best", np.nan)
            if algo in s.index and not isinstance(s.loc[algo], pd.DataFrame) else np.nan,
            "printed_position_error_mm": s.loc[algo].get("printed_position_error_mm", np.nan)
            if algo in s.index and not isinstance(s.loc[algo], pd.DataFrame) else np.nan})
    return pd.DataFrame(rows).dropna(axis=1, how="all")


def cases_table(exp) -> pd.DataFrame:
    """Fig. 7a: final position error (mm) per random pose and algorithm (all 100 poses, one run each)."""
    runs = exp.table("runs")
    wide = runs.pivot_table(index="case", columns="algorithm", values="position_error", aggfunc="median", sort=False)
    wide.columns = [f"{c}_position_error_mm" for c in wide.columns]
    return wide.reset_index()


def extra_tables(exp) -> list[tuple[str, pd.DataFrame]]:
    if exp.name == "tab2_tab3_fig5_fig6":
        return [("Tab. 2: the paper's printed joint solutions (deg) put through fkopt's forward kinematics: the "
                 "arm does not reach the target:", printed_solutions_table(exp)),
                ("Tab. 2: joint solutions (deg) of fkopt's median run per algorithm beside the printed ones:",
                 table2(exp)),
                ("Tab. 3 (deterministic columns; times in TIMING.md) over all runs, beside the printed values; "
                 "`share_meeting_requirement`: position <= 0.1 mm and Euler orientation <= 1e-3 rad (Sec. 3).",
                 table3(exp))]
    if exp.name in ("baselines", "pso_eq10"):
        return [("Over all runs: position and orientation errors (same columns as Tab. 3):", table3(exp))]
    if exp.name == "fig7":
        return [("Fig. 7a: final position error (mm) on every one of the random reachable poses:", cases_table(exp))]
    return []
