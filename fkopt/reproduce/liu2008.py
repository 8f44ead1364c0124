"""liu2008: 6-SPS parallel CMM forward kinematics by PSO (docs/models.md "liu2008").

Claims, notes and inconsistencies are data (configs/liu2008/claims.yaml); this module adds the
legs of the printed pose, the iterations-to-threshold table and the two numbers the claims name.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from fkopt.reproduce.claims import g

#: Printed leg lengths of Tab. 3 (m) and the printed pose (m, deg).
PRINTED_LEGS = (0.750, 0.780, 0.800, 0.900, 0.870, 0.850)
PRINTED_POSE = (0.039860, 0.095930, 0.925235, -12.697325, 6.403095, 15.133206)
#: Half a unit of the last printed digit of the pose (1e-6 m and 1e-6 deg printed).
PRINTED_HALF_UNIT = 5e-7


def _printed_pose_legs() -> pd.DataFrame:
    """Legs of the printed pose under fkopt's model vs the printed legs."""
    from fkopt.mechanisms.sps6 import SixSPSCMM
    legs = SixSPSCMM().ik(np.array([PRINTED_POSE]))[0]
    return pd.DataFrame({"leg": [f"l{i + 1}" for i in range(6)], "printed_m": PRINTED_LEGS,
                         "of_printed_pose_m": legs, "difference_um": (legs - np.array(PRINTED_LEGS)) * 1e6})


#: A run that reached the threshold farther than this from the exact solution (m, deg) found another
#: assembly mode: another forward solution of the same legs (a successful run lands within ~1e-4).
OTHER_MODE_TOL = 1e-3


def run_columns(exp, runs: pd.DataFrame) -> pd.DataFrame:
    """runs.csv plus ``failed`` (1: the run never reached the threshold), ``other_mode`` (1: it reached
    it on another assembly mode, > OTHER_MODE_TOL from the exact solution in some coordinate) and
    ``misses`` (either: the run did not find the paper's pose)."""
    failed = runs.iterations_to_threshold.isna()
    err = runs[[c for c in runs.columns if c.startswith("abs_error_")]].max(axis=1)
    other = ~failed & (err > OTHER_MODE_TOL)
    return runs.assign(failed=failed.astype(float), other_mode=other.astype(float),
                       misses=(failed | other).astype(float))


def printed_pose_in_half_units(store):
    """Largest |printed pose - exact solution| in half units of the printed last digit."""
    t3 = store.get("liu2008", "tab3_fig4")
    if t3 is None:
        return None
    v = t3.table("values")
    worst = float((v.printed_value - v.exact_solution).abs().max() / PRINTED_HALF_UNIT)
    legs = _printed_pose_legs()
    return worst, (f"every printed value is within {g(worst)} half units of its last digit of the exact solution; "
                   f"rounded so, it reproduces the legs only to {np.abs(legs.difference_um).max():.2f} um "
                   f"(sum {np.abs(legs.difference_um).sum():.2f} um > the 0.5 um precision)"), \
        {"largest_difference": worst * PRINTED_HALF_UNIT}


QUANTITIES = {"printed_pose_in_half_units": printed_pose_in_half_units}


def extra_tables(exp) -> list[tuple[str, pd.DataFrame]]:
    out = []
    if exp.name == "tab3_fig4":
        df = _printed_pose_legs()
        out.append(("Leg lengths of the printed Tab. 3 pose (fkopt's inverse map) vs the printed legs: up to "
                    f"{np.abs(df.difference_um).max():.2f} um apart, sum {np.abs(df.difference_um).sum():.2f} um:", df))
    runs = exp.table("runs")
    rows = []
    for algo, grp in runs.groupby("algorithm", sort=False):
        it = grp["iterations_to_threshold"]
        rows.append({"algorithm": algo, "runs": len(grp), "success_rate": float(it.notna().mean()),
                     "min_iterations": it.min(), "q25": it.quantile(0.25), "median": it.median(),
                     "q75": it.quantile(0.75), "max_iterations": it.max(),
                     "median_evaluations": grp["evaluations_to_threshold"].median()})
    out.append((f"Iterations to the threshold {exp.config['threshold']:g} over all runs (the paper: ~55 for its "
                "single run):", pd.DataFrame(rows)))
    return out
