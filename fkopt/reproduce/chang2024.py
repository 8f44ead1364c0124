"""chang2024: 3RPUPc-UPS forward kinematics, ABC vs PSO vs P-ABC (SPEC.md "chang2024").

Experiments: ``tab1_fig7`` (the printed case, 30 runs, Tab. 1 and Fig. 7), ``tab2`` (50 random
poses x 10 runs, Tab. 2) and ``baselines`` (the case beside LM, Newton and PSO+LM). Both the mechanism and
P-ABC are reconstructions of equations lost in the text extraction, and so are Tab. 1/Tab. 2's
numbers (only the orders of magnitude quoted in the text survive): the claims below are judged
against those quoted orders.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from .claims import Claim, g, missing, verdict

TITLE = ("Chang, Zhang, Zhang, Song, Li (2024), Forward kinematics of the 3RPUPc-UPS parallel "
         "mechanism based on a particle-artificial bee colony algorithm (paper 001_61129119fc937038.txt)")

EXPERIMENTS = ["tab1_fig7", "tab2", "baselines"]

#: The printed inputs of the case (alpha, beta, gamma, z) = (25, 34, 23, 360) (Sec. 3.3).
CASE_POSE = {"alpha": 25.0, "beta": 34.0, "gamma": 23.0, "z": 360.0}
PRINTED_INPUTS = {"l1": 332.048, "l2": 390.904, "l3": 402.294, "delta": -14.4389}
#: Orders of magnitude of the mean error quoted in the text (Tab. 1 itself was lost).
PRINTED_ORDERS = {"abc": 1e-18, "pso": 1e-10, "pabc": 1e-20}
PRINTED_TIME_SAVING = 0.5002        # P-ABC vs ABC, Tab. 1
PRINTED_SOLVE_S = 0.5               # Tab. 2: every P-ABC solve within 0.5 s
LEVEL = 1e-10                       # "solved" in the tables below (also the configs' threshold)
NAMES = {"abc": "ABC", "pso": "PSO", "pabc": "P-ABC"}

NOTES = [
    "**Reconstruction (mechanism):** the paper's kinematic equations (17)-(30) were lost in the text "
    "extraction. fkopt uses SPEC.md's model: base joints B1..B4 = (-R,0,0), (0,-R,0), (R,0,0), (0,R,0), "
    "R = 120 mm; platform circle c = 60 mm around Q = (0,0,z); R_p = Rx(-alpha) Ry(-beta) Rz(gamma); "
    "the RPUPc legs' U joints slide on the platform circle and stay in their legs' vertical planes; "
    "leg 4's input delta = atan2(dX, -dY) of C4 - B4. It reproduces the one printed case (inputs "
    "l = (332.048, 390.904, 402.294) mm, delta = -14.4389 deg) within the printed rounding.",
    "**Reconstruction (algorithm):** P-ABC's equations (34)-(40) were lost too. fkopt's `pabc`: PSO "
    "(w = 0.8, c1 = c2 = 2) for the first half of the iterations, then ABC whose food sources are the "
    "particles' personal bests (one source per particle), greedy selection throughout.",
    "**Chosen by fkopt (not printed):** search bounds alpha, beta, gamma in [-45, 45] deg, z in [300, "
    "420] mm (covering the case); ABC limit = population x dim = 400; PSO velocity clamp 0.2 of the box "
    "width (the printed w = 0.8, c1 = c2 = 2 lie outside PSO's convergence region c1 + c2 < 2(1 + w), "
    "so the swarm only settles thanks to the clamp); the error f_PS (eq. 32/33, lost) is the sum of "
    "squared input residuals (mm^2 for l1..l3 plus deg^2 for delta).",
    "**Lost tables:** Tab. 1 and Tab. 2 did not survive the extraction. The text quotes the orders of "
    "magnitude of the mean error (ABC 1e-18, PSO 1e-10, P-ABC 1e-20), a time saving of 50.02 % of "
    "P-ABC over ABC and single P-ABC solves within 0.5 s; those are what fkopt is compared with "
    "(`printed_error_order` in the tables). Tab. 2's 50 poses are unknown: fkopt draws 50 poses "
    "uniformly in its search box (seed 2024).",
    "**Budgets:** Tab. 1 the printed 30 runs; Tab. 2 10 runs per pose and algorithm (the paper's run "
    "count for Tab. 2 was lost), all 50 poses x 10 runs of an algorithm in one batched solve.",
    "Cost per iteration differs: an ABC iteration costs 2 x population evaluations, a PSO iteration "
    "population, a P-ABC run 1.5 x population on average, so at the same 300 iterations ABC spends a "
    "third more evaluations than P-ABC (compare `mean_evaluations`).",
    "Fitness 0 in the tables means the inputs were reproduced to the last bit of double precision.",
]


# -- helpers -----------------------------------------------------------------------------------
def _mechanism(exp=None):
    from .. import registry
    if exp is None:
        return registry.mechanism_class("3-rpupc-ups")()
    m = exp.config["mechanism"]
    return registry.mechanism_class(m["name"])(bounds=dict(m.get("bounds") or {}), **(m.get("geometry") or {}))


def inputs_table() -> pd.DataFrame:
    """fkopt's inverse map of the printed case beside the printed inputs (Sec. 3.3)."""
    mech = _mechanism()
    pose = mech.vector(CASE_POSE, mech.pose_names, "case")
    computed = mech.ik(pose)
    rows = []
    for name, unit, c in zip(mech.joint_names, mech.joint_units, computed):
        p = PRINTED_INPUTS[name]
        rows.append({"input": name, "unit": unit, "printed": f"{p:.4f}", "fkopt_inverse_map": f"{c:.5f}",
                     "difference": float(c - p)})
    return pd.DataFrame(rows)


def curve_table(exp, iterations=(0, 50, 100, 150, 200, 250, 300)) -> pd.DataFrame:
    """Median best-so-far fitness (and mean evaluations) per algorithm at a few iterations (Fig. 7)."""
    c = exp.table("convergence")
    rows = []
    for algo, grp in c.groupby("algorithm", sort=False):
        grp = grp.set_index("iteration")
        row = {"algorithm": algo}
        for t in iterations:
            if t in grp.index:
                row[f"it_{t}"] = float(grp.loc[t, "median"])
        row["evaluations_at_end"] = float(grp["mean_evaluations"].iloc[-1])
        rows.append(row)
    return pd.DataFrame(rows)


def _median_at(exp, algo: str, t: int) -> float:
    c = exp.table("convergence")
    c = c[(c.algorithm == algo) & (c.iteration == t)]
    return float(c["median"].iloc[0])


def _max_errors(runs: pd.DataFrame) -> pd.DataFrame:
    runs = runs.copy()
    runs["max_angle_error_deg"] = runs[["abs_error_alpha", "abs_error_beta", "abs_error_gamma"]].max(axis=1)
    runs["z_error_mm"] = runs["abs_error_z"]
    return runs


def poses_table(exp) -> pd.DataFrame:
    """Tab. 2: per pose, the target, each algorithm's fitness and P-ABC's pose errors (medians over the
    pose's runs)."""
    runs = _max_errors(exp.table("runs"))
    v = exp.table("values")
    targets = v[v.algorithm == v.algorithm.iloc[0]].pivot(index="case", columns="variable", values="target")
    order = list(dict.fromkeys(runs["case"]))
    med = runs.groupby(["case", "algorithm"], sort=False)
    out = targets.loc[order, ["alpha", "beta", "gamma", "z"]].reset_index()
    for algo in dict.fromkeys(runs["algorithm"]):
        fit = med.final_fitness.median().xs(algo, level="algorithm")
        out[f"fitness_{algo}"] = out["case"].map(fit)
    if "pabc" in set(runs["algorithm"]):
        p = runs[runs.algorithm == "pabc"].groupby("case", sort=False)
        out["pabc_max_angle_error_deg"] = out["case"].map(p.max_angle_error_deg.median())
        out["pabc_z_error_mm"] = out["case"].map(p.z_error_mm.median())
    return out


def poses_summary(exp) -> pd.DataFrame:
    """Over all poses (and runs) per algorithm: share solved, fitness and pose error spread."""
    runs = _max_errors(exp.table("runs"))
    rows = []
    for algo, grp in runs.groupby("algorithm", sort=False):
        f = grp.final_fitness
        rows.append({"algorithm": algo, "poses": grp["case"].nunique(), "runs": len(grp),
                     f"share_below_{LEVEL:g}": float((f < LEVEL).mean()),
                     "median_fitness": float(f.median()), "worst_fitness": float(f.max()),
                     "median_max_angle_error_deg": float(grp.max_angle_error_deg.median()),
                     "worst_max_angle_error_deg": float(grp.max_angle_error_deg.max()),
                     "worst_z_error_mm": float(grp.z_error_mm.max()),
                     "mean_evaluations": float(grp.evaluations.mean())})
    return pd.DataFrame(rows)


def extra_tables(exp) -> list[tuple[str, pd.DataFrame]]:
    if exp.name == "tab1_fig7":
        return [
            ("Sec. 3.3: the printed inputs of the case beside fkopt's inverse map of (25, 34, 23 deg, "
             "360 mm) (reconstructed model):", inputs_table()),
            ("Fig. 7 in numbers: median best-so-far fitness over the 30 runs at iterations 0-300 (P-ABC "
             "switches from PSO to ABC at 150):", curve_table(exp)),
        ]
    if exp.name == "tab2":
        return [
            (f"Tab. 2 over the 50 random poses x 10 runs per algorithm: share of runs below "
             f"{LEVEL:g}, fitness and pose errors:", poses_summary(exp)),
            ("Tab. 2 per pose: the target pose, each algorithm's final fitness, and P-ABC's largest angle "
             "error and z error (times per pose in TIMING.md):", poses_table(exp)),
        ]
    if exp.name == "baselines":
        return [("Baselines over all runs (same columns as the Tab. 2 summary):", poses_summary(exp))]
    return []


# -- claims ------------------------------------------------------------------------------------
def claims(store) -> list[Claim]:
    out: list[Claim] = []
    inp = inputs_table()
    tol = {"l1": 5e-4, "l2": 5e-4, "l3": 5e-4, "delta": 5e-5}
    out.append(Claim(
        "Sec. 3.3: the case (25 deg, 34 deg, 23 deg, 360 mm) has inputs l = (332.048, 390.904, 402.294) "
        "mm, delta = -14.4389 deg (reconstructed model)",
        verdict(all(abs(r.difference) <= tol[r.input] for r in inp.itertuples())),
        "fkopt's inverse map: " + ", ".join(f"{r.input} {r.fkopt_inverse_map} ({r.difference:+.1e})"
                                            for r in inp.itertuples())))
    t1 = store.get("chang2024", "tab1_fig7")
    if t1 is None:
        out.append(missing("Tab. 1/Fig. 7 claims", "chang2024/tab1_fig7"))
    else:
        s = {a: t1.row("summary", algorithm=a) for a in ("abc", "pso", "pabc")}
        dec = {a: np.log10(max(float(s[a].mean_fitness), 1e-300)) - np.log10(PRINTED_ORDERS[a]) for a in s}
        out.append(Claim(
            "Tab. 1: mean error over 30 runs of order 1e-18 (ABC), 1e-10 (PSO), 1e-20 (P-ABC)",
            verdict(all(abs(d) <= 1.0 for d in dec.values())),
            "mean final fitness " + ", ".join(f"{NAMES[a]} {g(s[a].mean_fitness)} ({dec[a]:+.1f} decades)"
                                              for a in ("abc", "pso", "pabc"))))
        ev_pabc = float(s["pabc"].mean_evaluations)
        c = t1.table("convergence")
        c = c[(c.algorithm == "abc") & (c.mean_evaluations >= ev_pabc)]
        at_equal = (f"; at P-ABC's {ev_pabc:.0f} evaluations ABC's median was {g(float(c['median'].iloc[0]))} "
                    f"(iteration {int(c.iteration.iloc[0])})") if len(c) else ""
        out.append(Claim(
            "Tab. 1: P-ABC is more precise than ABC (error level 1e-18 -> 1e-20)",
            verdict(s["pabc"].mean_fitness < s["abc"].mean_fitness and s["pabc"].median_fitness < s["abc"].median_fitness),
            f"mean / median final fitness P-ABC {g(s['pabc'].mean_fitness)} / {g(s['pabc'].median_fitness)}, "
            f"ABC {g(s['abc'].mean_fitness)} / {g(s['abc'].median_fitness)} at the same 300 iterations{at_equal}"))
        gain = np.log10(max(float(s["pso"].mean_fitness), 1e-300)) - np.log10(max(float(s["pabc"].mean_fitness), 1e-300))
        out.append(Claim(
            "Tab. 1 / Sec. 4: P-ABC is 10 orders of magnitude more precise than PSO (1e-10 -> 1e-20)",
            verdict(gain >= 9.0),
            f"mean final fitness PSO {g(s['pso'].mean_fitness)} vs P-ABC {g(s['pabc'].mean_fitness)}: "
            f"{gain:.1f} orders (success rate at {LEVEL:g}: PSO {g(s['pso'].success_rate)}, P-ABC "
            f"{g(s['pabc'].success_rate)})"))
        T = int(t1.config["iterations"])
        half = T // 2   # 150 of 300: P-ABC's switch from PSO to ABC
        m150 = {a: _median_at(t1, a, half) for a in s}
        m300 = {a: _median_at(t1, a, T) for a in s}
        out.append(Claim(
            "Fig. 7: in the first 150 iterations ABC converges faster than PSO and P-ABC",
            verdict(m150["abc"] < min(m150["pso"], m150["pabc"])),
            f"median best fitness at iteration {half}: " + ", ".join(f"{NAMES[a]} {g(m150[a])}" for a in s)))
        drop = {a: np.log10(max(m150[a], 1e-300)) - np.log10(max(m300[a], 1e-300)) for a in s}
        gained = (f"decades gained by the median from iteration {half} to {T}: "
                  + ", ".join(f"{NAMES[a]} {drop[a]:.1f}" for a in s))
        out.append(Claim(
            "Fig. 7: after iteration 150 PSO converges slowly while P-ABC accelerates away from PSO",
            verdict(drop["pabc"] > drop["pso"] + 2.0), gained))
        out.append(Claim(
            "Fig. 7: after iteration 150 ABC's curve stays flat (ABC stalls)",
            verdict(drop["abc"] < 1.0), gained))
        out.append(Claim(
            "Fig. 7: at iteration 300 P-ABC's fitness is far below ABC's and PSO's",
            verdict(m300["pabc"] * 10 < min(m300["abc"], m300["pso"])),
            f"median best fitness at iteration {T}: " + ", ".join(f"{NAMES[a]} {g(m300[a])}" for a in s)))
        ev = {a: float(s[a].mean_evaluations) for a in s}
        out.append(Claim(
            "Tab. 1: P-ABC costs less than ABC (50.02 % less time); deterministic side: function "
            "evaluations of the 300 iterations",
            verdict(ev["pabc"] < ev["abc"]),
            f"mean evaluations per run P-ABC {ev['pabc']:.0f} vs ABC {ev['abc']:.0f} "
            f"({100 * (1 - ev['pabc'] / ev['abc']):.1f} % fewer; PSO {ev['pso']:.0f}); times in TIMING.md"))
    t2 = store.get("chang2024", "tab2")
    if t2 is None:
        out.append(missing("Tab. 2 claims", "chang2024/tab2"))
    else:
        ps = poses_summary(t2).set_index("algorithm")
        p = ps.loc["pabc"]
        out.append(Claim(
            "Tab. 2: P-ABC solves every one of 50 poses with an error of order 1e-20 (300 iterations)",
            verdict(p.worst_fitness < 1e-19),
            f"P-ABC over {int(p.poses)} random poses: median fitness {g(p.median_fitness)}, worst "
            f"{g(p.worst_fitness)}, share below {LEVEL:g} {g(p[f'share_below_{LEVEL:g}'])}; largest angle "
            f"error {g(p.worst_max_angle_error_deg)} deg, z error {g(p.worst_z_error_mm)} mm"))
        runs = t2.table("runs")
        piv = runs.pivot_table(index="case", columns="algorithm", values="final_fitness", aggfunc="median")
        wins_abc = int((piv["pabc"] < piv["abc"]).sum())
        wins_pso = int((piv["pabc"] < piv["pso"]).sum())
        out.append(Claim(
            "Tab. 2 (beyond Tab. 1's single case): P-ABC is more precise than ABC and PSO across poses",
            verdict(wins_abc > len(piv) / 2 and wins_pso > len(piv) / 2),
            f"P-ABC's fitness lower than ABC's on {wins_abc} of {len(piv)} poses, lower than PSO's on "
            f"{wins_pso}; median fitness ABC {g(ps.loc['abc'].median_fitness)}, PSO "
            f"{g(ps.loc['pso'].median_fitness)}, P-ABC {g(p.median_fitness)}"))
    return out


def timing_claims(store) -> list[Claim]:
    out: list[Claim] = []
    t1 = store.get("chang2024", "tab1_fig7")
    if t1 is not None:
        t = t1.table("timing").set_index("algorithm")["mean_ms_per_run"]
        saving = 1.0 - t["pabc"] / t["abc"]
        out.append(Claim(
            "Tab. 1: P-ABC's run time is 50.02 % shorter than ABC's",
            verdict(abs(saving - PRINTED_TIME_SAVING) <= 0.1),
            f"mean ms per run P-ABC {g(t['pabc'])} vs ABC {g(t['abc'])}: {100 * saving:.1f} % shorter "
            f"(judged held within 10 points of 50.02 %)"))
        out.append(Claim(
            "Tab. 1: P-ABC takes longer than PSO",
            verdict(t["pabc"] > t["pso"]),
            f"mean ms per run P-ABC {g(t['pabc'])}, PSO {g(t['pso'])}"))
    t2 = store.get("chang2024", "tab2")
    if t2 is not None:
        t = t2.table("timing")
        p = t[t.algorithm == "pabc"]["mean_ms_per_run"]
        out.append(Claim(
            "Tab. 2: every single P-ABC solve takes less than 0.5 s",
            verdict(p.max() < 1e3 * PRINTED_SOLVE_S),
            f"P-ABC ms per solve over {len(p)} poses: median {g(p.median())}, max {g(p.max())}"))
    return out
