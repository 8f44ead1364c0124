"""liu2008: 6-SPS parallel CMM forward kinematics by PSO (docs/models.md "liu2008").

Claims, notes and inconsistencies are data (configs/liu2008/claims.yaml); this module adds the
legs of the printed pose, the iterations-to-threshold table and the two numbers the claims name.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from fkopt.mechanisms.sps6 import SixSPSCMM
from fkopt.numerics.rotations import geodesic_angle, zyx
from fkopt.reproduce.claims import g

#: Printed leg lengths of Tab. 3 (m) and the printed pose (m, deg).
PRINTED_LEGS = (0.750, 0.780, 0.800, 0.900, 0.870, 0.850)
PRINTED_POSE = (0.039860, 0.095930, 0.925235, -12.697325, 6.403095, 15.133206)
#: Half a unit of the last printed digit of the pose (1e-6 m and 1e-6 deg printed).
PRINTED_HALF_UNIT = 5e-7


def _printed_pose_legs() -> pd.DataFrame:
    """Legs of the printed pose under fkopt's model vs the printed legs."""
    legs = SixSPSCMM().ik(np.array([PRINTED_POSE]))[0]
    return pd.DataFrame({"leg": [f"l{i + 1}" for i in range(6)], "printed_m": PRINTED_LEGS,
                         "of_printed_pose_m": legs, "difference_um": (legs - np.array(PRINTED_LEGS)) * 1e6})


#: A run that reached the threshold farther than this from the exact solution (m in position, deg of
#: rotation) found another assembly mode: another forward solution of the same legs (a successful run
#: lands within ~1e-4).
OTHER_MODE_TOL = 1e-3


def pose_distance(exp, runs: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """Per run: (position distance in m, rotation angle in deg) between the run's pose and its case's
    exact solution (the config's ``reference``).

    The rotation is compared as a rotation (the geodesic angle of R_run^T R_exact, R = Rz(gamma)
    Ry(beta) Rx(alpha), SPEC.md "Rotation matrix used by mao2017 and liu2008"), never as raw Euler
    differences: (alpha + 180, 180 - beta, gamma + 180) deg, or any angle plus 360 deg, is the same
    orientation, and Newton's unclipped steps land there (newton_starts run 263 of Newton: the Tab. 3
    pose written with alpha = -8472.7, beta = 173.6, gamma = -9164.9 deg).
    """
    refs = {str(c.get("label")): c.get("reference") for c in (exp.config.get("cases") or [])}
    missing = sorted({str(k) for k in runs["case"].astype(str)} - {k for k, v in refs.items() if v})
    if missing:
        raise ValueError(f"{exp.paper}/{exp.name}: case {missing[0]!r} has no reference pose to compare runs with")
    ref = pd.DataFrame([refs[str(k)] for k in runs["case"].astype(str)], index=runs.index)
    position = np.sqrt(sum((runs[f"x_{v}"] - ref[v]).to_numpy(float) ** 2 for v in ("x", "y", "z")))
    rad = lambda df, prefix: [np.radians(df[f"{prefix}{v}"].to_numpy(float)) for v in ("alpha", "beta", "gamma")]  # noqa: E731
    angle = np.degrees(geodesic_angle(zyx(*rad(runs, "x_")), zyx(*rad(ref, ""))))
    return position, angle


def run_columns(exp, runs: pd.DataFrame) -> pd.DataFrame:
    """runs.csv plus ``failed`` (1: the run never reached the threshold), ``other_mode`` (1: it reached
    it on another assembly mode, more than OTHER_MODE_TOL from the exact solution in position (m) or
    in rotation (deg, :func:`pose_distance`: equivalent Euler angles are the same pose)) and
    ``misses`` (either: the run did not find the paper's pose)."""
    failed = runs.iterations_to_threshold.isna()
    position, angle = pose_distance(exp, runs)
    other = ~failed & ((position > OTHER_MODE_TOL) | (angle > OTHER_MODE_TOL))
    return runs.assign(failed=failed.astype(float), other_mode=other.astype(float),
                       misses=(failed | other).astype(float), position_distance_m=position, rotation_deg=angle)


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
