"""wang7dof: 7-DOF redundant arm inverse kinematics, ABC vs PSO (docs/models.md "wang7dof")."""
from __future__ import annotations

import numpy as np
import pandas as pd

from .claims import Claim, compare, equal_budget, faster_claim, g, missing, verdict

TITLE = ("Wang et al., Inverse kinematics of a redundant manipulator based on the artificial bee "
         "colony algorithm: 7-DOF arm, ABC vs PSO (paper 004_9e97004859498dea.txt)")

EXPERIMENTS = ["tab2_tab3_fig5_fig6", "pso_eq10", "baselines", "fig7"]

#: Tab. 2's printed joint solutions (deg); the PSO column lost its decimal points ("48 282").
PRINTED_JOINTS = {
    "pso": (48.282, -6.758, 47.497, 34.208, 50.654, -60.107, -30.0),
    "abc": (101.19, -9.52, -14.32, 4.36, 39.68, 35.94, 72.68),
}
TARGET_JOINTS = (45.0, 0.0, 45.0, 0.0, 45.0, 0.0, 0.0)
#: Sec. 3 accuracy requirement: position error <= 0.1 mm, orientation error <= 1e-3 (unit garbled
#: as "mm"; read as rad, i.e. 0.0573 deg).
POSITION_REQUIREMENT_MM = 0.1
ORIENTATION_REQUIREMENT_DEG = float(np.degrees(1e-3))

NOTES = [
    "Model: the standard-DH 7-DOF arm of docs/models.md, a = (0, 200, 250, 300, 200, 200, 100) mm, "
    "alpha = (-90, 90, -90, 90, -90, 0, 0) deg, d = (500, 0, 0, 0, 0, 0, 50) mm. **Typos in the "
    "paper's Tab. 1:** the twists are printed in \"rad\" but are degrees, and the upper limit of "
    "joint 7 is printed \"900\"; fkopt uses (-30, 90) deg.",
    "Target: the pose of q = (45, 0, 45, 0, 45, 0, 0) deg, position (-247.4874, 1009.6194, 500.0000) "
    "mm, Z-Y-Z Euler angles (-135, 90, -90) deg. Objective as printed (eqs. 3-5, `objective: paper`): "
    "f = dP + (180/pi) dR, dP the position distance in mm, dR the norm of the Z-Y-Z Euler-angle "
    "differences in rad (each wrapped to +-180 deg), so f reads mm + deg. Every wang7dof experiment "
    "here uses this paper objective; fkopt also offers `objective: geodesic` (rotation angle of "
    "R_target^T R), free of the Euler singularity at sin(beta) = 0.",
    "Settings as printed: ABC population 100, PSO population 300, 500 iterations. Not printed, fkopt's "
    "defaults: ABC limit = population x 7, neighbour factor phi in [-1, 1] (the paper's eq. 7 prints "
    "rand(0, 1)), quality 1/(1 + f) (the paper: 1/f); PSO constriction weights w = 0.7298, "
    "c1 = c2 = 1.49618, v_max = 0.2 x box width (the paper's eq. 10 has no inertia weight and gives no "
    "constants). One ABC iteration costs ~200 evaluations, one PSO iteration 300.",
    "**PSO as printed (eq. 10):** v(t+1) = v(t) + c1 r1 (pbest - x) + c2 r2 (gbest - x), x(t+1) = x(t) + "
    "v(t): no inertia weight (w = 1) and no constants. `pso_eq10` runs that form (w = 1, c1 = c2 = 2 as "
    "in Kennedy & Eberhart 1995, velocity clamp 0.2 x box width, without which w = 1 diverges) beside "
    "fkopt's constriction PSO.",
    "**Budgets as in the paper:** Tab. 3 50 runs; Fig. 7 100 random reachable poses with 1 run each "
    "(all poses of an algorithm in one batched solve). `baselines` reruns the first 10 runs of Tab. 3 "
    "exactly (same seed) beside Levenberg-Marquardt and ABC+LM.",
    "\"Iterations to best\" is the first iteration at which a run's final best-so-far fitness was "
    "reached (`iterations_to_best` in runs.csv); swarms that still improve by tiny steps at the end "
    "get values near 500. \"Time to best\" (TIMING.md) is each timed single run's time scaled by "
    "its iterations_to_best / 500.",
    "**Known errors in the paper:** (1) the printed joint solutions of Tab. 2 do not reach the target "
    "under the paper's own DH table: fk puts ABC's solution 85.9 mm and PSO's 126.1 mm from the target "
    "position, 104 and 69 deg off in orientation (table below), so the paper's solutions cannot be "
    "checked. (2) The text says ABC is more precise than PSO, while Tab. 3 prints position errors "
    "ABC 4.75e-3 mm > PSO 3.71e-3 mm; the Fig. 5 text gives ABC 4.883e-3 mm, the Fig. 6 text and the "
    "abstract 'below 1e-4 mm'. (3) The Fig. 6b text says ABC's 500 iterations take slightly less "
    "time than PSO's, while Tab. 3 prints ABC 0.8884 s > PSO 0.7612 s.",
]


def _problem(exp):
    """The IK problem of the experiment's first case, rebuilt from its recorded config."""
    from ..experiment.config import ExperimentConfig
    from ..experiment.runner import build_cases, build_mechanism, build_problem

    cfg = ExperimentConfig(**exp.config)
    mech = build_mechanism(cfg)
    return mech, build_problem(cfg, mech, build_cases(cfg, mech)[0])


def errors_of(problem, joints) -> dict[str, np.ndarray]:
    """Position error (mm), paper (Euler) and geodesic orientation errors (deg) of joint vectors."""
    q = np.atleast_2d(np.asarray(joints, dtype=float))
    return {"position_error_mm": problem.position_error(q),
            "euler_error_deg": problem.rotation_error(q, "paper"),
            "geodesic_error_deg": problem.rotation_error(q, "geodesic"),
            "fitness": problem.fitness(q)}


def printed_solutions_table(exp) -> pd.DataFrame:
    """fk of Tab. 2's printed joint vectors and their errors against the target."""
    mech, pr = _problem(exp)
    rows = []
    for algo, q in PRINTED_JOINTS.items():
        pose = mech.fk(np.array([q]))[0]
        e = errors_of(pr, q)
        rows.append({"printed_solution": algo, **{n: v for n, v in zip(mech.joint_names, q)},
                     **{f"fk_{n}": v for n, v in zip(mech.pose_names, pose)},
                     **{k: float(v[0]) for k, v in e.items()}})
    return pd.DataFrame(rows)


def _runs_with_errors(exp) -> pd.DataFrame:
    """runs.csv plus the Euler and geodesic orientation errors of every run's joints."""
    mech, pr = _problem(exp)
    runs = exp.table("runs")
    q = runs[[f"x_{n}" for n in mech.joint_names]].to_numpy()
    for k, v in errors_of(pr, q).items():
        if k != "fitness":
            runs[k] = v
    runs["meets_requirement"] = ((runs.position_error_mm <= POSITION_REQUIREMENT_MM)
                                 & (runs.euler_error_deg <= ORIENTATION_REQUIREMENT_DEG))
    return runs


def _median_run(grp: pd.DataFrame) -> pd.Series:
    order = grp.sort_values("final_fitness", kind="stable")
    return order.iloc[(len(order) - 1) // 2]


def table2(exp) -> pd.DataFrame:
    """Tab. 2: joint solution of the median run of each algorithm beside the printed ones."""
    mech, _ = _problem(exp)
    runs = _runs_with_errors(exp)
    printed = printed_solutions_table(exp).set_index("printed_solution")
    rows = [{"solution": "target", **dict(zip(mech.joint_names, TARGET_JOINTS)),
             "position_error_mm": 0.0, "euler_error_deg": 0.0, "geodesic_error_deg": 0.0}]
    for algo, grp in runs.groupby("algorithm", sort=False):
        m = _median_run(grp)
        rows.append({"solution": f"fkopt {algo} (median run {int(m.run)})",
                     **{n: m[f"x_{n}"] for n in mech.joint_names},
                     **{k: m[k] for k in ("position_error_mm", "euler_error_deg", "geodesic_error_deg")}})
        if algo in printed.index:
            p = printed.loc[algo]
            rows.append({"solution": f"printed {algo}", **{n: p[n] for n in mech.joint_names},
                         **{k: p[k] for k in ("position_error_mm", "euler_error_deg", "geodesic_error_deg")}})
    return pd.DataFrame(rows)


def table3(exp) -> pd.DataFrame:
    """Tab. 3 (deterministic part): iterations to best and position error over all runs."""
    runs = _runs_with_errors(exp)
    conv = exp.table("convergence")
    s = exp.table("summary").set_index("algorithm")
    rows = []
    for algo, grp in runs.groupby("algorithm", sort=False):
        c = conv[conv.algorithm == algo]["median"].to_numpy()
        rows.append({
            "algorithm": algo, "population": int(s.loc[algo, "population"]), "iterations": int(s.loc[algo, "iterations"]),
            "runs": len(grp),
            "median_iterations_to_best": grp.iterations_to_best.median(),
            "median_curve_within_1pct_at": int(np.argmax(c <= c[-1] * 1.01)),
            "median_position_error_mm": grp.position_error_mm.median(),
            "mean_position_error_mm": grp.position_error_mm.mean(),
            "best_position_error_mm": grp.position_error_mm.min(),
            "median_euler_error_deg": grp.euler_error_deg.median(),
            "median_geodesic_error_deg": grp.geodesic_error_deg.median(),
            "median_fitness": grp.final_fitness.median(),
            "share_meeting_requirement": grp.meets_requirement.mean(),
            "printed_iterations_to_best": s.loc[algo].get("printed_iterations_to_best", np.nan),
            "printed_position_error_mm": s.loc[algo].get("printed_position_error_mm", np.nan),
        })
    return pd.DataFrame(rows).dropna(axis=1, how="all")


def cases_table(exp) -> pd.DataFrame:
    """Fig. 7a: final position/orientation error per random pose and algorithm (median over runs)."""
    runs = _runs_with_errors_all_cases(exp)
    agg = runs.groupby(["case", "algorithm"], sort=False)[
        ["position_error_mm", "euler_error_deg", "final_fitness"]].median().reset_index()
    wide = agg.pivot(index="case", columns="algorithm", values="position_error_mm")
    wide = wide.loc[agg.case.unique()]
    wide.columns = [f"{c}_position_error_mm" for c in wide.columns]
    return wide.reset_index()


def _runs_with_errors_all_cases(exp) -> pd.DataFrame:
    from ..experiment.config import ExperimentConfig
    from ..experiment.runner import build_cases, build_mechanism, build_problem

    cfg = ExperimentConfig(**exp.config)
    mech = build_mechanism(cfg)
    cases = build_cases(cfg, mech)
    runs = exp.table("runs")
    out = []
    for case in cases:
        pr = build_problem(cfg, mech, case)
        part = runs[runs.case == case.label].copy()
        q = part[[f"x_{n}" for n in mech.joint_names]].to_numpy()
        for k, v in errors_of(pr, q).items():
            if k != "fitness":
                part[k] = v
        out.append(part)
    return pd.concat(out, ignore_index=True)


def extra_tables(exp) -> list[tuple[str, pd.DataFrame]]:
    if exp.name == "tab2_tab3_fig5_fig6":
        return [
            ("Tab. 2: the paper's printed joint solutions (deg) put through fkopt's forward kinematics: "
             "the arm does not reach the target (orientation errors: Euler-difference norm and "
             "geodesic angle):", printed_solutions_table(exp)),
            ("Tab. 2: joint solutions (deg) of fkopt's median run per algorithm beside the printed ones, "
             "with their errors against the target:", table2(exp)),
            ("Tab. 3 (deterministic columns; times are in TIMING.md): over all runs, beside the printed "
             "values. `share_meeting_requirement`: position error <= 0.1 mm and Euler orientation error "
             "<= 1e-3 rad (Sec. 3).", table3(exp)),
        ]
    if exp.name == "baselines":
        return [("Baselines over all runs: position and orientation errors (same columns as Tab. 3):",
                 table3(exp))]
    if exp.name == "fig7":
        return [("Fig. 7a: final position error (mm) per random reachable pose:", cases_table(exp))]
    return []


NAMES = {"abc": "ABC", "pso": "PSO", "pso_eq10": "PSO (eq. 10)"}


def _per_run(runs: pd.DataFrame, algo: str, column: str) -> np.ndarray:
    return runs[runs.algorithm == algo].sort_values(["case", "run"])[column].to_numpy(float)


def _evaluations_to_best(exp, algo: str) -> np.ndarray:
    """Per run: evaluations spent when its final best-so-far was first reached (trace.csv.gz)."""
    t = exp.table("trace")
    t = t[t.algorithm == algo]
    last = t.sort_values(["run", "iteration"]).groupby("run").tail(1).set_index("run").best_fitness
    first = t[t.best_fitness.to_numpy() == t.run.map(last).to_numpy()].groupby("run").evaluations.min()
    return first.sort_index().to_numpy(float)


def claims(store) -> list[Claim]:
    out: list[Claim] = []
    t3 = store.get("wang7dof", "tab2_tab3_fig5_fig6")
    if t3 is None:
        out.append(missing("Tab. 2/3 claims", "wang7dof/tab2_tab3_fig5_fig6"))
    else:
        p = printed_solutions_table(t3).set_index("printed_solution")
        out.append(Claim(
            "Tab. 2: the printed joint solutions of ABC and PSO bring the arm to the target "
            "(position errors of a few 1e-3 mm, Tab. 3)",
            verdict(p.position_error_mm.max() < 0.1),
            f"fk of the printed joints: ABC {g(p.loc['abc', 'position_error_mm'])} mm and "
            f"{g(p.loc['abc', 'geodesic_error_deg'])} deg, PSO {g(p.loc['pso', 'position_error_mm'])} mm "
            f"and {g(p.loc['pso', 'geodesic_error_deg'])} deg from the target",
            {"position_error_abc": float(p.loc["abc", "position_error_mm"]),
             "position_error_pso": float(p.loc["pso", "position_error_mm"])}))
        runs = _runs_with_errors(t3)
        t = table3(t3).set_index("algorithm")
        a, s = t.loc["abc"], t.loc["pso"]
        cb = compare("ABC", _per_run(runs, "abc", "iterations_to_best"), "PSO", _per_run(runs, "pso", "iterations_to_best"))
        ce = (compare("ABC", _evaluations_to_best(t3, "abc"), "PSO", _evaluations_to_best(t3, "pso"))
              if t3.has("trace.csv.gz") else None)
        out.append(Claim(
            "Tab. 3: ABC reaches its best solution in fewer iterations than PSO (115 vs 311)",
            verdict(cb.lower == "ABC"),
            f"iterations to each run's final best: {cb.text()}; evaluations to it: "
            f"{ce.text() if ce else 'n/a (no per-run trace)'}; median curve within 1 % of its end at ABC "
            f"{g(a.median_curve_within_1pct_at)}, PSO {g(s.median_curve_within_1pct_at)}",
            {"p": cb.p, "lower": cb.lower, "median_abc": cb.median_a, "median_pso": cb.median_b}
            | ({"p_evaluations": ce.p, "lower_evaluations": ce.lower} if ce else {})))
        out.append(Claim(
            "Tab. 3: both reach position errors of a few 1e-3 mm (ABC 4.75e-3, PSO 3.71e-3 mm)",
            verdict(max(a.median_position_error_mm, s.median_position_error_mm) < 1e-2),
            f"median final position error ABC {g(a.median_position_error_mm)} mm, PSO "
            f"{g(s.median_position_error_mm)} mm (mean {g(a.mean_position_error_mm)}, "
            f"{g(s.mean_position_error_mm)}; best {g(a.best_position_error_mm)}, {g(s.best_position_error_mm)})",
            {"median_position_error_abc": float(a.median_position_error_mm),
             "median_position_error_pso": float(s.median_position_error_mm)}))
        cp = compare("ABC", _per_run(runs, "abc", "position_error_mm"), "PSO", _per_run(runs, "pso", "position_error_mm"))
        it, ev, budget = equal_budget(t3, "abc", "pso", NAMES)
        out.append(Claim(
            "Abstract/Sec. 4, Fig. 6a: ABC's position error is smaller than PSO's, its search precision better "
            "(while Tab. 3 prints 4.75e-3 vs 3.71e-3 mm)",
            verdict(cp.lower == "ABC"),
            f"final position error at equal iterations (500): {cp.text()}, PSO about "
            f"{cp.median_a / max(cp.median_b, 1e-300):.0f}x smaller; the objective f = dP + dR (mm + deg) at equal "
            f"iterations: {it.text()}; at equal evaluations ({budget:.0f}): {ev.text() if ev else 'n/a'}",
            {"p": cp.p, "lower": cp.lower, "median_abc_mm": cp.median_a, "median_pso_mm": cp.median_b,
             "p_fitness_iterations": it.p, "lower_fitness_iterations": it.lower}))
        out.append(Claim(
            "Abstract/Fig. 6a: ABC's position error settles below 1e-4 mm",
            verdict(a.median_position_error_mm < 1e-4),
            f"ABC median {g(a.median_position_error_mm)} mm, best run {g(a.best_position_error_mm)} mm",
            {"median_position_error_abc": float(a.median_position_error_mm)}))
        out.append(Claim(
            "Sec. 3: the solutions reach the target within the accuracy requirement (position <= 0.1 mm and "
            "orientation <= 1e-3 rad)",
            verdict(min(a.share_meeting_requirement, s.share_meeting_requirement) >= 0.5),
            f"neither algorithm reaches the target pose: share of runs meeting both ABC "
            f"{g(a.share_meeting_requirement)}, PSO {g(s.share_meeting_requirement)}; median orientation error "
            f"(Euler norm) ABC {g(a.median_euler_error_deg)} deg, PSO {g(s.median_euler_error_deg)} deg, against "
            f"{ORIENTATION_REQUIREMENT_DEG:.3g} deg",
            {"share_abc": float(a.share_meeting_requirement), "share_pso": float(s.share_meeting_requirement),
             "euler_error_abc": float(a.median_euler_error_deg), "euler_error_pso": float(s.median_euler_error_deg)}))
    eq = store.get("wang7dof", "pso_eq10")
    if eq is not None:
        r = _runs_with_errors(eq)
        ce = compare("PSO (eq. 10)", _per_run(r, "pso_eq10", "position_error_mm"), "PSO",
                     _per_run(r, "pso", "position_error_mm"))
        out.append(Claim(
            "Eq. 10: the PSO as printed (no inertia weight) is the PSO compared in Tab. 3 (position error 3.71e-3 mm)",
            verdict(float(np.median(ce.values_a)) < 1e-2),
            f"final position error, PSO as printed (w = 1, c1 = c2 = 2, clamped) vs fkopt's constriction PSO: "
            f"{ce.text()}",
            {"median_eq10_mm": ce.median_a, "median_constriction_mm": ce.median_b, "p": ce.p}))
    bl = store.get("wang7dof", "baselines")
    if bl is None:
        out.append(missing("baseline claims", "wang7dof/baselines"))
    else:
        t = table3(bl).set_index("algorithm")
        sm = bl.table("summary").set_index("algorithm")
        best_swarm = min(t.loc["abc", "median_position_error_mm"], t.loc["pso", "median_position_error_mm"])
        rb = bl.table("runs")
        cl = compare("LM", _per_run(rb, "lm", "final_fitness"), "PSO", _per_run(rb, "pso", "final_fitness"))
        out.append(Claim(
            "Introduction: swarm search is the better route to a redundant arm's IK than the numerical "
            "(Jacobian) methods the paper lists",
            verdict(cl.lower == "PSO"),
            f"final f, LM (one random start, <= 100 iterations) vs PSO: {cl.text()}; LM in "
            f"{g(sm.loc['lm', 'mean_evaluations'])} evaluations, success at f < 0.1 {g(sm.loc['lm', 'success_rate'])}; "
            f"ABC+LM {g(t.loc['abc+lm', 'median_fitness'])} (success {g(sm.loc['abc+lm', 'success_rate'])}); ABC "
            f"{g(t.loc['abc', 'median_fitness'])}; best swarm median position error {g(best_swarm)} mm",
            {"p": cl.p, "lower": cl.lower}))
    f7 = store.get("wang7dof", "fig7")
    if f7 is None:
        out.append(missing("Fig. 7 claims", "wang7dof/fig7"))
    else:
        r = _runs_with_errors_all_cases(f7)
        c = compare("ABC", _per_run(r, "abc", "position_error_mm"), "PSO", _per_run(r, "pso", "position_error_mm"))
        per = cases_table(f7)
        n = len(per)
        out.append(Claim(
            f"Fig. 7a: on random poses ABC's position error is smaller than PSO's (fkopt: {n} poses)",
            verdict(c.lower == "ABC"),
            f"final position error over all poses and runs: {c.text()}; ABC smaller on "
            f"{int((per.abc_position_error_mm < per.pso_position_error_mm).sum())} of {n} poses",
            {"p": c.p, "lower": c.lower, "median_abc_mm": c.median_a, "median_pso_mm": c.median_b}))
    return out


def _time_to_best(exp, algo: str) -> tuple[np.ndarray, np.ndarray]:
    """Per timed single run: (ms to its best = ms x iterations_to_best / iterations, ms of all iterations)."""
    t = exp.table("timing_runs")
    t = t[t.algorithm == algo]
    runs = exp.table("runs")
    runs = runs[runs.algorithm == algo].set_index(["case", "run"]).iterations_to_best
    it = np.array([runs.loc[(c, k)] for c, k in zip(t["case"], t.run)], dtype=float)
    total = float(exp.row("summary", algorithm=algo).iterations if exp.table("summary")["case"].nunique() == 1
                  else exp.config["iterations"])
    return t.ms.to_numpy() * it / total, t.ms.to_numpy()


def timing_claims(store) -> list[Claim]:
    out = []
    for name, label in (("tab2_tab3_fig5_fig6", "Tab. 3"), ("fig7", "Fig. 7b")):
        exp = store.get("wang7dof", name)
        if exp is None or not exp.has("timing_runs.csv"):
            continue
        (ab, aa), (pb, pa) = _time_to_best(exp, "abc"), _time_to_best(exp, "pso")
        text = ("Tab. 3: ABC finds its best solution in less time than PSO (0.2087 s vs 0.4768 s)" if name != "fig7"
                else "Fig. 7b: on random poses ABC generally needs less time than PSO to find its best solution")
        out.append(faster_claim(text, "ABC", compare("ABC", ab, "PSO", pb)))
        out[-1].evidence = "time to best (single-run ms x iterations to best / iterations), " + out[-1].evidence
        if name != "fig7":
            out.append(faster_claim("Tab. 3: 500 iterations take ABC longer than PSO (0.8884 s vs 0.7612 s; the "
                                    "Fig. 6b text says the opposite)", "PSO", compare("PSO", pa, "ABC", aa)))
    return out
