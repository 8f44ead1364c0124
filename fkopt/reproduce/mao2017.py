"""mao2017: 3-RPS forward kinematics, ACO vs ABC vs GABC (docs/models.md "mao2017").

Claims, notes and the paper's inconsistencies are data (configs/mao2017/claims.yaml); this module
measures the three numbers no generic kind can: how the printed leg lengths relate to the printed
pose (Sec. 3) and to the paper's ACO answer (Tab. 2).
"""
from __future__ import annotations

import numpy as np

from fkopt.reproduce.claims import g

POSE = {"alpha": 9.0, "beta": 13.0, "z": 622.0}
PRINTED_ACO = {"alpha": 8.85983, "beta": 13.0018, "z": 621.999}   # Tab. 2's ACO row
EXACT = "exact_solution_of_printed_d"


def printed_legs_difference_mm(store):
    """Largest |printed d - fkopt's inverse map of (9, 13, 622)| (mm)."""
    pi = store.get("mao2017", "printed_inputs")
    if pi is None:
        return None
    inp = pi.table("inputs")
    worst = float(inp.difference.abs().max())
    return worst, ("fkopt's inverse map of the pose differs from the printed d by "
                   + ", ".join(f"{r.joint} {r.difference:+.4f}" for r in inp.itertuples()) + " mm"), \
        {"max_difference_mm": worst}


def _exact(pi) -> dict[str, float]:
    v = pi.table("values")
    v = v[v.algorithm == "gabc"]
    return dict(zip(v.variable, v[EXACT]))


def printed_legs_mean_error_vs_exact(store):
    """Mean over all GABC runs of |x - exact solution of the printed d|, largest coordinate."""
    pi = store.get("mao2017", "printed_inputs")
    if pi is None:
        return None
    exact = _exact(pi)
    r = pi.table("runs")
    r = r[r.algorithm == "gabc"]
    means = {k: float(np.mean(np.abs(r[f"x_{k}"] - x))) for k, x in exact.items()}
    worst = max(means.values())
    return worst, (f"mean over all {len(r)} GABC runs of |x - exact|: "
                   + ", ".join(f"{k} {g(m)}" for k, m in means.items())), {"max_difference_from_exact": worst}


def aco_row_pose_minus_exact_distance(store):
    """(distance of the paper's ACO answer to the pose) - (its distance to the exact solution of the
    printed d): negative if it solved the same inputs as the ABC/GABC rows."""
    pi = store.get("mao2017", "printed_inputs")
    if pi is None:
        return None
    exact = _exact(pi)
    d_exact = max(abs(PRINTED_ACO[k] - exact[k]) for k in PRINTED_ACO)
    d_pose = max(abs(PRINTED_ACO[k] - POSE[k]) for k in PRINTED_ACO)
    return d_pose - d_exact, (f"the paper's ACO answer (8.85983, 13.0018, 621.999) is within {g(d_exact)} of the "
                              f"exact solution of the printed leg lengths but {g(d_pose)} from the pose (9, 13, 622) "
                              "that its ABC/GABC rows solve"), {"aco_to_exact": d_exact, "aco_to_pose": d_pose}


QUANTITIES = {f.__name__: f for f in (printed_legs_difference_mm, printed_legs_mean_error_vs_exact,
                                      aco_row_pose_minus_exact_distance)}
