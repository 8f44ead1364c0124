"""``fkopt bench --section fksgp``: every real forward solution of general 6-6 Stewart-Gough
platforms, fkopt's ``all_solutions`` beside fkSGP (Martyushev, "Forward kinematics of a general
Stewart-Gough platform by elimination templates", Mech. Mach. Theory 215, 2025: all 40 complex
solutions from one elimination template; MIT), whose Python code is not on the package index:
it is measured from a vendored snapshot, ``../shared/vendor/fksgp`` beside the repository (or
the folder in ``FKSGP_PATH``), and the section is skipped with a message when there is none.

Per platform (:data:`PLATFORMS`; :data:`QUICK_PLATFORMS` in quick mode): base and platform points as fkSGP's
``genSGP`` draws them (first point at the origin, the others uniform in [-2, 2]^3), from a
seeded generator; a pose with a Cayley rotation of a standard normal vector and a standard
normal translation; the squared leg lengths of that pose (fkSGP's input) and the leg lengths
(fkopt's). fkopt: ``fkopt.mechanism("6-sps", base=..., platform=...)`` (its default bounds: a
position box of twice the mechanism's size, full-turn angles) and
:func:`fkopt.kinematics.assembly_modes.all_solutions` with its defaults. fkSGP: ``solver66(X,
x, L, realOnly=1)``, its random rotations drawn from numpy's global generator seeded per
platform (the global state restored afterwards). The two alternate (which goes first
alternates too), after one warm-up call each; times are wall clock per instance, and the
process CPU time of each call (all threads: fkopt's tracker spreads its 40 paths over numba's
threads, fkSGP's LAPACK calls may use BLAS threads) is reported beside it.

The solution sets are compared as rigid motions (R, t): a solution of one matches one of the
other when max |R - R'| and max |t - t'| / (1 + |t|) are below :data:`MATCH`. Rows: the median
over platforms of fkopt's time over fkSGP's, with its quartiles (target <= 1, issue 38), and
how many platforms gave the same set (fkSGP's solutions inside fkopt's bounds only; outside
them fkopt does not look).
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

import fkopt
from fkopt.tools.bench.measuring import load_average
from fkopt.kinematics.assembly_modes import all_solutions
from fkopt.numerics import rotations

#: Platforms per full run (issue 38 asks for at least 30) and in quick mode.
PLATFORMS = 30
QUICK_PLATFORMS = 5
#: Two solutions are the same rigid motion below this (rotation entries; translation relative).
MATCH = 1e-6
#: Issue 38: fkopt's time per instance over fkSGP's, median over platforms.
FKSGP_TARGET = 1.0


def fksgp_folder() -> Path | None:
    """The vendored fkSGP snapshot: ``FKSGP_PATH``, else ``../shared/vendor/fksgp`` beside the
    repository or the working directory; None when there is none."""
    here = Path(__file__).resolve().parents[3]
    for p in filter(None, [os.environ.get("FKSGP_PATH"), here.parent / "shared/vendor/fksgp",
                           Path.cwd().parent / "shared/vendor/fksgp"]):
        p = Path(p)
        if (p / "python" / "solver66.py").is_file():
            return p
    return None


def _cayley(p):
    T = np.array([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]])
    return np.linalg.solve(np.eye(3) - T, np.eye(3) + T).T        # as fkSGP's cayley.py


def _rigid(pose):
    """(R, t) of a 6-sps pose (x, y, z, alpha, beta, gamma in deg, Z-Y-X)."""
    a, b, g = np.radians(pose[3:6])
    return np.array(rotations.zyx(a, b, g), dtype=float), np.asarray(pose[:3], dtype=float)


def _same_sets(ours, theirs, inside) -> tuple[int, int, int]:
    """(matched, fkopt's solutions fkSGP lacks, fkSGP's solutions inside the bounds fkopt lacks)."""
    used = [False] * len(ours)
    missing = 0
    for (R, t), ok in zip(theirs, inside):
        hit = next((i for i, (R1, t1) in enumerate(ours) if not used[i] and np.abs(R - R1).max() < MATCH
                    and np.abs(t - t1).max() < MATCH * (1 + np.abs(t).max())), None)
        if hit is None:
            missing += bool(ok)
        else:
            used[hit] = True
    return sum(used), len(ours) - sum(used), missing


def bench_fksgp(rows, quick: bool, messages: list[str]) -> None:
    folder = fksgp_folder()
    if folder is None:
        messages.append("fksgp: section skipped: no vendored fkSGP snapshot (../shared/vendor/fksgp beside the "
                        "repository, or FKSGP_PATH); it is not on the package index")
        return
    sys.path.insert(0, str(folder))
    try:
        from python.solver66 import solver66
    except Exception as err:                         # pragma: no cover - depends on the snapshot
        messages.append(f"fksgp: section skipped: fkSGP does not import from {folder} ({type(err).__name__}: {err})")
        return
    finally:
        sys.path.remove(str(folder))
    n = QUICK_PLATFORMS if quick else PLATFORMS
    rng = np.random.default_rng(20261206)
    ratios, cpu_ratios, same, counts, methods = [], [], 0, [], []
    t_f, t_s, c_f, c_s = [], [], [], []
    for k in range(n):
        X = np.vstack([np.zeros((1, 3)), 4 * rng.random((5, 3)) - 2])
        x = np.vstack([np.zeros((1, 3)), 4 * rng.random((5, 3)) - 2])
        R0, t0 = _cayley(rng.standard_normal(3)), rng.standard_normal(3)
        A = R0 @ x.T + t0[:, None] - X.T
        L2 = np.sum(A * A, axis=0)
        m = fkopt.mechanism("6-sps", base=X.tolist(), platform=x.tolist())
        legs = np.sqrt(L2)

        def theirs():
            state = np.random.get_state()
            np.random.seed(k)
            try:
                return solver66(X, x, L2, 1)
            finally:
                np.random.set_state(state)

        def ours():
            return all_solutions(m, legs, seed=k)
        if k == 0:
            theirs(), ours()                         # warm-up: imports, compiled kernels, start tables
        got = {}
        for who in ((0, 1) if k % 2 else (1, 0)):
            t, c = time.perf_counter(), time.process_time()
            got[who] = (ours if who == 0 else theirs)()
            (t_f if who == 0 else t_s).append(time.perf_counter() - t)
            (c_f if who == 0 else c_s).append(time.process_time() - c)
        sols = got[0]
        methods.append(sols.method)
        Rt, err = got[1]
        mine = [_rigid(p) for p in sols.poses()]
        lo, hi = m.bounds[:, 0], m.bounds[:, 1]
        other, inside = [], []
        for i in range(len(Rt)):
            R, t = Rt[i, :, :3], Rt[i, :, 3]
            other.append((R, t))
            # its pose in fkopt's coordinates, to tell whether fkopt's bounds hold it
            beta = -np.arcsin(np.clip(R[2, 0], -1, 1))
            alpha, gamma = np.arctan2(R[2, 1], R[2, 2]), np.arctan2(R[1, 0], R[0, 0])
            pose = np.r_[t, np.degrees([alpha, beta, gamma])]
            inside.append(bool(np.all(pose >= lo - 1e-9) and np.all(pose <= hi + 1e-9)))
        matched, extra, missing = _same_sets(mine, other, inside)
        same += extra == 0 and missing == 0
        counts.append((len(mine), len(other), matched))
        ratios.append(t_f[-1] / t_s[-1])
        cpu_ratios.append(c_f[-1] / max(c_s[-1], 1e-9))
    r, rc = np.array(ratios), np.array(cpu_ratios)
    med = float(np.median(r))
    rows.add("fksgp", "6-6 all real solutions / fkSGP", med, "x",
             f"median over {n} random general 6-6 platforms of fkopt all_solutions' time over fkSGP solver66's "
             f"(realOnly), alternating; quartiles {np.quantile(r, 0.25):.2f}-{np.quantile(r, 0.75):.2f}, range "
             f"{r.min():.2f}-{r.max():.2f}; fkopt median {np.median(t_f) * 1e3:.1f} ms, fkSGP "
             f"{np.median(t_s) * 1e3:.1f} ms; load average {load_average()}; target <= {FKSGP_TARGET:g}: "
             f"{'met' if med <= FKSGP_TARGET else 'NOT met'}; fkopt's method: "
             f"{', '.join(f'{methods.count(x)} {x}' for x in sorted(set(methods)))}")
    rows.add("fksgp", "6-6 all real solutions / fkSGP, CPU time", float(np.median(rc)), "x",
             f"median over the same platforms of fkopt's process CPU time (all threads) over fkSGP's, per call; "
             f"quartiles {np.quantile(rc, 0.25):.2f}-{np.quantile(rc, 0.75):.2f}; fkopt median "
             f"{np.median(c_f) * 1e3:.1f} ms, fkSGP {np.median(c_s) * 1e3:.1f} ms")
    rows.add("fksgp", "platforms with the same real solution set", same, "of " + str(n),
             f"solutions fkopt / fkSGP / matched per platform: "
             f"{', '.join(f'{a}/{b}/{c}' for a, b, c in counts)} (fkSGP's outside fkopt's bounds not counted)")
