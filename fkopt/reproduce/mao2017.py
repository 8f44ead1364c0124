"""mao2017: 3-RPS forward kinematics, ACO vs ABC vs GABC (docs/models.md "mao2017")."""
from __future__ import annotations

import numpy as np

from .claims import (NOT_CHECKABLE, Claim, compare, equal_budget, better_claim, faster_claim, first_below, g,
                     missing, p_text, timing_comparison, verdict)

TITLE = ("Mao, Xie, Wu, Yuan (2017), Forward kinematics optimization of 3-RPS parallel manipulator "
         "based on global-best artificial bee colony algorithm (paper 000_cc8e52ccaff28014.txt)")

EXPERIMENTS = ["tab2_tab3_fig2", "tab3_floor", "tab4_tab5_fig3", "tab6", "printed_inputs", "baselines"]

NOTES = [
    "Model: the 3-RPS of docs/models.md with parasitic motions (eq. 6); r_a = 274 mm, r_b = 158 mm; workspace "
    "alpha, beta in [-20, 20] deg, z in [400, 700] mm; population 10, 600 iterations, 30 runs.",
    "**Known error in the paper:** the printed leg lengths d = (598.8495, 671.5847, 629.4955) mm for "
    "(9 deg, 13 deg, 622 mm) do not match the paper's own equations, which give (598.8458, 671.9171, "
    "629.1616) mm: 0.33 mm off on d2 and d3. The exact forward solution of the printed d is "
    "(8.85873 deg, 13.00352 deg, 622.00677 mm), next to the paper's own ACO answer (8.85983, 13.0018, "
    "621.999). fkopt computes the inputs from the pose by default; `printed_inputs` solves the printed d.",
    "**Typo in the paper:** Tab. 6 prints beta = 7 as the true value of pose 3 but solves -7.00013; "
    "fkopt uses -7.",
    "GABC update rule: the paper's eq. (19) as printed (`rule: mao2017`, one phi in both terms) is the "
    "default; Zhu & Kwong's original (`rule: zhu2010`) is available.",
    "ACO is wu2015's improved continuous ACO with fkopt's documented step sizes (the paper does not "
    "print its ACO settings), so the ACO rows compare a re-implementation, not the authors' code.",
    "Fitness 0 in the tables means the leg lengths were reproduced to the last bit of double precision "
    "(the target inputs come from fkopt's own inverse map).",
    "**Tab. 3's floor explained:** Karaboga's ABC selects greedily on fit = 1/(1+f). In double precision "
    "1/(1+f) == 1 for every f below ~1.1e-16, so such an ABC cannot tell improvements apart under that "
    "floor and keeps the first source it finds below it. fkopt compares raw f by default (and reaches 0); "
    "`selection: karaboga` compares 1/(1+f) and reproduces the printed 5.4e-17 / 4.1e-17 "
    "(`tab3_floor`). The paper's Fig. 2 curves end on that floor, so its convergence iterations are read "
    "at 1e-16.",
    "**The paper's stop is not its tables' stop:** Tab. 5 and Tab. 6 print final fitness values of "
    "4.8e-5 to 6.0e-5, above the 1e-5 threshold at which their runs are said to stop.",
    "**The ACO row is not like for like:** the paper's ACO answer (8.85983, 13.0018, 621.999) is the "
    "exact solution of the printed, inconsistent leg lengths (8.85873, 13.00352, 622.00677) to within 0.008, "
    "while its ABC/GABC answers are the pose (9, 13, 622): its ACO solved different inputs.",
]

NAMES = {"aco": "ACO", "abc": "ABC", "gabc": "GABC (eq. 19)", "gabc_zhu2010": "GABC (Zhu & Kwong)"}
FLOOR = 1e-16   # the floor of the paper's Fig. 2 curves (Tab. 3's ~5e-17 level)
PRINTED_FLOOR = {"abc": (5.41289e-17, 2.68715e-17), "gabc": (4.10317e-17, 2.11369e-17)}
PRINTED_ITERATIONS = {"abc": 170, "gabc": 90}
PRINTED_STOP_FITNESS = (4.76015e-5, 5.97693e-5)   # smallest / largest printed in Tab. 5 and 6




def _row(exp, algo, table="summary", **where):
    return exp.row(table, algorithm=algo, **where)


def claims(store) -> list[Claim]:
    out: list[Claim] = []
    fl = store.get("mao2017", "tab3_floor")
    t3 = store.get("mao2017", "tab2_tab3_fig2")
    if fl is None or t3 is None:
        out.append(missing("Tab. 3 floor", "mao2017/tab3_floor and mao2017/tab2_tab3_fig2"))
    else:
        m = {a: _row(fl, a) for a in ("abc", "gabc")}
        dec = {a: abs(np.log10(m[a].mean_fitness / PRINTED_FLOOR[a][0])) for a in m}
        raw = {a: _row(t3, a).mean_fitness for a in ("abc", "gabc")}
        out.append(Claim(
            "Tab. 3: ABC and GABC reach a mean final fitness of 5.41e-17 +- 2.69e-17 and 4.10e-17 +- 2.11e-17 "
            "over 30 runs (600 iterations)",
            verdict(max(dec.values()) <= 0.5),
            f"selecting on fit = 1/(1+f) as Karaboga's code does (tab3_floor): ABC {g(m['abc'].mean_fitness)} +- "
            f"{g(m['abc'].std_fitness)}, GABC {g(m['gabc'].mean_fitness)} +- {g(m['gabc'].std_fitness)} (within "
            f"{max(dec.values()):.2f} decades of the printed means); selecting on raw f (fkopt's default) both "
            f"reach {g(raw['abc'])} / {g(raw['gabc'])}: the printed level is the resolution of 1/(1+f) "
            "(== 1 below 1.1e-16), not of the kinematics",
            {"mean_abc": float(m["abc"].mean_fitness), "mean_gabc": float(m["gabc"].mean_fitness),
             "std_abc": float(m["abc"].std_fitness), "std_gabc": float(m["gabc"].std_fitness),
             "raw_mean_abc": float(raw["abc"]), "raw_mean_gabc": float(raw["gabc"])}))
        it, ev, budget = equal_budget(fl, "gabc", "abc", NAMES)
        out.append(better_claim("Tab. 3: GABC is more precise than ABC (mean 4.10e-17 vs 5.41e-17)", NAMES["gabc"],
                                it, ev, budget, int(fl.config["iterations"])))
        out[-1].evidence = "with Karaboga's selection (tab3_floor), " + out[-1].evidence
    if t3 is None:
        out.append(missing("Tab. 2/3 and Fig. 2 claims", "mao2017/tab2_tab3_fig2"))
    else:
        it, ev, budget = equal_budget(t3, "aco", "abc", NAMES)
        out.append(Claim(
            "Tab. 3: ACO's error is far larger than ABC's and GABC's (mean 5.69e-3 vs ~5e-17)",
            NOT_CHECKABLE,
            "the paper's ACO solved the printed, inconsistent leg lengths (its answer lies within 0.008 of their exact "
            "solution, see below) and its settings are not printed, so its 5.69e-3 is not like for like; fkopt's "
            f"re-implemented ACO on the consistent inputs: equal iterations (600): {it.text()}; equal "
            f"evaluations ({budget:.0f}): {ev.text() if ev else 'n/a (no per-run trace)'}",
            {"p_iterations": it.p, "median_aco": it.median_a, "median_abc": it.median_b}))
    if t3 is not None and not t3.has("trace.csv.gz"):
        out.append(missing("Fig. 2 claims", "mao2017/tab2_tab3_fig2/trace.csv.gz (per-run traces)"))
    elif t3 is not None:
        runs = {a: first_below(t3, a, FLOOR) for a in ("abc", "gabc", "gabc_zhu2010")}
        med = {a: float(np.median(runs[a][0])) for a in runs}
        med_ev = {a: float(np.median(runs[a][1])) for a in runs}
        out.append(Claim(
            "Fig. 2: ABC converges (reaches the curves' floor, ~1e-16) in ~170 iterations",
            verdict(abs(med["abc"] - PRINTED_ITERATIONS["abc"]) <= 0.25 * PRINTED_ITERATIONS["abc"]),
            f"median iteration at which a run's best-so-far first goes below {FLOOR:g}: ABC {g(med['abc'])} "
            f"(judged held within 25 % of 170)",
            {"median_iterations_abc": med["abc"]}))
        gv = compare(NAMES["gabc"], runs["gabc"][0], NAMES["abc"], runs["abc"][0])
        gve = compare(NAMES["gabc"], runs["gabc"][1], NAMES["abc"], runs["abc"][1])
        zv = compare(NAMES["gabc_zhu2010"], runs["gabc_zhu2010"][0], NAMES["abc"], runs["abc"][0])
        out.append(Claim(
            "Fig. 2: GABC (eq. 19 as printed) converges fastest, in ~90 iterations (ABC ~170)",
            verdict(gv.lower == NAMES["gabc"] and abs(med["gabc"] - 90) <= 0.25 * 90),
            f"iterations to {FLOOR:g} per run, {gv.text()}; evaluations: {gve.text()}. Zhu & Kwong's original "
            f"rule: {g(med['gabc_zhu2010'])} iterations ({med_ev['gabc_zhu2010']:.0f} evaluations), vs ABC "
            f"{p_text(zv.p)}: the paper's GABC curve matches Zhu & Kwong's rule, not its printed eq. 19",
            {"median_iterations_gabc": med["gabc"], "median_iterations_zhu": med["gabc_zhu2010"],
             "p_gabc_abc": gv.p, "p_zhu_abc": zv.p, "lower_gabc_abc": gv.lower, "lower_zhu_abc": zv.lower}))
    if t3 is not None:
        v = t3.table("values")
        err = float(v[v.algorithm.isin(["abc", "gabc"])]["mean_abs_error"].max())
        out.append(Claim(
            "Tab. 2: ABC and GABC solve every variable with an error below 1e-10",
            verdict(err < 1e-10),
            f"largest mean absolute error over all runs and variables (ABC, GABC): {g(err)}",
            {"max_mean_abs_error": err}))
    t5 = store.get("mao2017", "tab4_tab5_fig3")
    if t5 is None:
        out.append(missing("Tab. 4/5 claims", "mao2017/tab4_tab5_fig3"))
    else:
        abc, gabc, aco = (_row(t5, a) for a in ("abc", "gabc", "aco"))
        out.append(Claim(
            "Tab. 5: stopping at fitness < 1e-5, ACO cannot reach the precision within 600 iterations",
            NOT_CHECKABLE,
            "the paper's ACO settings are not printed and its ACO solved other inputs (the printed leg lengths); "
            f"fkopt's re-implemented ACO: share of runs reaching 1e-5 {g(aco.success_rate)} (ABC "
            f"{g(abc.success_rate)}, GABC {g(gabc.success_rate)})",
            {"success_aco": float(aco.success_rate)}))
        r = t5.table("runs")
        ri = {a: r[r.algorithm == a].sort_values("run") for a in ("abc", "gabc")}
        ci = compare(NAMES["gabc"], ri["gabc"].iterations_to_threshold, NAMES["abc"], ri["abc"].iterations_to_threshold)
        ce = compare(NAMES["gabc"], ri["gabc"].evaluations_to_threshold, NAMES["abc"], ri["abc"].evaluations_to_threshold)
        out.append(Claim(
            "Fig. 3: stopping at fitness < 1e-5, GABC converges in fewer iterations than ABC (its Tab. 5 "
            "times, 38.3 vs 69.8 ms, are judged in TIMING.md)",
            verdict(ci.lower == NAMES["gabc"]),
            f"iterations to 1e-5 per run: {ci.text()}; evaluations: {ce.text()}; run times judged in TIMING.md",
            {"p_iterations": ci.p, "p_evaluations": ce.p, "median_gabc": ci.median_a, "median_abc": ci.median_b,
             "lower_iterations": ci.lower}))
        v = t5.table("values")
        err = float(v[v.algorithm.isin(["abc", "gabc"])]["median_run_abs_error"].max())
        out.append(Claim(
            "Tab. 4: at fitness < 1e-5 the absolute errors are ~1e-4 (engineering requirement)",
            verdict(err < 1e-3),
            f"largest median-run absolute error (ABC, GABC) at the 1e-5 stop: {g(err)}. The paper's own Tab. 5 "
            f"fitness values ({g(abc.printed_mean_fitness)}, {g(gabc.printed_mean_fitness)}) exceed its 1e-5 "
            "stop, so its runs did not stop where it says",
            {"max_median_run_abs_error": err}))
    t6 = store.get("mao2017", "tab6")
    if t6 is None:
        out.append(missing("Tab. 6 claims", "mao2017/tab6"))
    else:
        s, v = t6.table("summary"), t6.table("values")
        out.append(Claim(
            "Tab. 6: GABC solves all five poses to fitness < 1e-5",
            verdict(s.success_rate.min() == 1.0),
            f"success rate per pose {', '.join(g(x) for x in s.success_rate)}; median iterations per pose "
            f"{', '.join(g(x) for x in s.median_iterations_to_threshold)}",
            {"min_success_rate": float(s.success_rate.min())}))
        err = float(v.median_run_abs_error.max())
        out.append(Claim(
            "Tab. 6: at that precision every pose variable is within ~3.4e-4 of the truth (10^-4 requirement)",
            verdict(err <= 5e-4),
            f"largest median-run absolute error {g(err)}; largest mean absolute error over all runs "
            f"{g(v.mean_abs_error.max())} (the paper's largest: 3.41e-4, with printed final fitness "
            f"{g(PRINTED_STOP_FITNESS[0])}..{g(PRINTED_STOP_FITNESS[1])}, above its 1e-5 stop)",
            {"max_median_run_abs_error": err}))
    pi = store.get("mao2017", "printed_inputs")
    if pi is None:
        out.append(missing("printed inputs", "mao2017/printed_inputs"))
    else:
        inp = pi.table("inputs")
        worst = float(inp.difference.abs().max())
        out.append(Claim(
            "Sec. 3: the printed leg lengths (598.8495, 671.5847, 629.4955) mm belong to the pose "
            "(9 deg, 13 deg, 622 mm)",
            verdict(worst < 1e-3),
            f"fkopt's inverse map of that pose differs by up to {g(worst)} mm "
            f"({', '.join(f'{r.joint} {r.difference:+.4f}' for r in inp.itertuples())})",
            {"max_difference_mm": worst}))
        v = pi.table("values")
        ref = [c for c in v.columns if c.startswith("median_run_error_vs_")]
        if ref:
            gv = v[v.algorithm == "gabc"]
            worst_ref = float(gv[ref[0]].max())
            out.append(Claim(
                "Solving the printed leg lengths gives the exact solution (8.85873, 13.00352, 622.00677), "
                "not (9, 13, 622)",
                verdict(worst_ref < 1e-4),
                f"GABC median run: {', '.join(f'{r.variable}={r.median_run_value:.5f}' for r in gv.itertuples())}"
                f" (largest difference from the exact solution {g(worst_ref)})",
                {"max_difference_from_exact": worst_ref}))
            exact = dict(zip(gv.variable, gv[ref[0].removeprefix("median_run_error_vs_")]))
            aco = {"alpha": 8.85983, "beta": 13.0018, "z": 621.999}
            d_exact = max(abs(aco[k] - exact[k]) for k in aco)
            d_pose = max(abs(aco[k] - t) for k, t in zip(("alpha", "beta", "z"), (9.0, 13.0, 622.0)))
            out.append(Claim(
                "Tab. 2/3: the ACO row solves the same inputs as the ABC and GABC rows",
                verdict(d_pose < d_exact),
                f"the paper's ACO answer (8.85983, 13.0018, 621.999) is within {g(d_exact)} of the exact "
                f"solution of the printed leg lengths but {g(d_pose)} from the pose (9, 13, 622) that its "
                "ABC/GABC rows solve: its ACO solved the printed, inconsistent inputs",
                {"aco_to_exact": d_exact, "aco_to_pose": d_pose}))
    return out


def timing_claims(store) -> list[Claim]:
    out = []
    t3 = store.get("mao2017", "tab2_tab3_fig2")
    if t3 is not None:
        for algo in ("abc", "gabc"):
            out.append(faster_claim(
                f"Tab. 3: {NAMES[algo]} takes longer per run than ACO ({'362.4' if algo == 'abc' else '361.3'}"
                " vs 250.6 ms)", NAMES["aco"], timing_comparison(t3, "aco", algo, NAMES)))
        c = faster_claim("Tab. 3: a GABC run is shorter than an ABC run (361.3 vs 362.4 ms, a 0.3 % difference)",
                         NAMES["gabc"], timing_comparison(t3, "gabc", "abc", NAMES))
        c.evidence += "; the printed difference itself (0.3 %) is smaller than any run-to-run spread"
        out.append(c)
    t5 = store.get("mao2017", "tab4_tab5_fig3")
    if t5 is not None:
        c = faster_claim("Tab. 5: with the 1e-5 stop, GABC runs faster than ABC (38.3 vs 69.8 ms)",
                         NAMES["gabc"], timing_comparison(t5, "gabc", "abc", NAMES))
        out.append(c)
        if t5.has("timing_runs.csv"):
            t = t5.table("timing_runs")
            worst = float(t[t.algorithm.isin(["abc", "gabc"])].ms.max())
            out.append(Claim("Tab. 5: with the 1e-5 stop, every ABC and GABC run meets the 100 ms real-time "
                             "requirement", verdict(worst < 100),
                             f"slowest timed single run (ABC, GABC): {g(worst)} ms", {"worst_ms": worst}))
    return out
