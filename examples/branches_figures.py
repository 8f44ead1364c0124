"""The two figures of docs/robots.md "Every solution of a pose, and paths on one branch":

* ``docs/figures/ur5_branches.png`` -- every solution of one UR5 pose (fkopt.inverse(...,
  solutions="all")), each arm drawn from its joint origins, side by side, same view;
* ``docs/figures/path_traces.png`` -- a path's joint traces: one answer per waypoint
  (fkopt.inverse, no start: the start table's nearest configuration each time) against
  fkopt.inverse_path (each waypoint from the previous answer).

    PYTHONPATH=. python examples/branches_figures.py [--out docs/figures]
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

import fkopt

ROBOTS = Path(__file__).resolve().parents[1] / "configs" / "suites" / "robots"


def joint_origins(m, q_deg) -> np.ndarray:
    """Points (m + 2, 3): the base, every moving joint's origin, the tip, from the arm's chain
    (fkopt.numerics.chain: F_i = F_{i-1} C_i Rz(q_i), origin p_i = p_{i-1} + F_{i-1} v_i)."""
    ch = m.chain()
    angle = m.angle_mask(m.joint_units)
    t = [math.radians(v) if a else v for v, a in zip(q_deg, angle)]
    F, p = np.eye(3), np.zeros(3)
    pts = [p.copy()]
    for i in range(len(ch.var)):
        qi = t[ch.var[i]] * ch.mult[i] + ch.off[i]
        p = p + F @ ch.v[i]
        F = F @ ch.C[i]
        pts.append(p.copy())
        if ch.prismatic[i]:
            p = p + F[:, 2] * qi
        else:
            c, s = math.cos(qi), math.sin(qi)
            F = F @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    pts.append(p + F @ ch.tail_v)
    return np.array(pts)


def branches_figure(out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    m = fkopt.mechanism("urdf", file=str(ROBOTS / "ur5.urdf"), base="base_link", tip="tool0")
    q = np.array([30.0, -60.0, 80.0, -40.0, 70.0, 20.0])
    T = m.fk_matrix(q[None])[0]
    r = fkopt.inverse(m, T, solutions="all")
    k = len(r)
    cols = 4
    rows = math.ceil(k / cols)
    fig = plt.figure(figsize=(3.2 * cols, 3.3 * rows))
    for i, s in enumerate(r.solutions):
        ax = fig.add_subplot(rows, cols, i + 1, projection="3d")
        P = joint_origins(m, s)
        ax.plot(P[:, 0], P[:, 1], P[:, 2], "-o", color="tab:blue", lw=2.5, ms=3.5)
        ax.plot([P[-1, 0]], [P[-1, 1]], [P[-1, 2]], "*", color="tab:red", ms=11)
        ax.plot([0], [0], [0], "s", color="k", ms=6)
        ax.set_xlim(-0.6, 0.6)
        ax.set_ylim(-0.6, 0.6)
        ax.set_zlim(-0.3, 0.9)
        ax.view_init(elev=22, azim=-60)
        ax.set_xticklabels([])
        ax.set_yticklabels([])
        ax.set_zticklabels([])
        ax.set_title(" ".join(f"{v:.0f}" for v in s), fontsize=8)
    fig.suptitle(f"UR5: the {k} solutions of one pose inside the limits (joints in deg; red star: the tool, "
                 f"the same pose in every panel)", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "ur5_branches.png", dpi=110)
    plt.close(fig)


def path_figure(out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    m = fkopt.mechanism("urdf", file=str(ROBOTS / "ur5.urdf"), base="base_link", tip="tool0")
    q0 = np.array([-20.0, -100.0, 70.0, -60.0, -80.0, 40.0])
    q1 = np.array([60.0, -60.0, 110.0, -120.0, -40.0, 100.0])
    Q = q0 + np.linspace(0, 1, 100)[:, None] * (q1 - q0)
    T = m.fk_matrix(Q)
    fresh = fkopt.inverse(m, T).joints
    follow = fkopt.inverse_path(m, T, start=Q[0])
    fig, axes = plt.subplots(1, 2, figsize=(12, 4), sharey=True)
    for ax, J, title in ((axes[0], fresh, "fkopt.inverse, one answer per waypoint (no start)"),
                         (axes[1], follow.joints, "fkopt.inverse_path (each waypoint from the previous answer)")):
        for j in range(m.dof):
            ax.plot(J[:, j], lw=1.6, label=m.joint_names[j])
        steps = np.degrees(np.abs(np.diff(np.radians(J), axis=0)).max(axis=1))
        jumps = np.flatnonzero(steps > math.degrees(0.05)) + 1
        for k in jumps:
            ax.axvline(k, color="0.6", lw=0.8, ls=":")
        ax.set_title(f"{title}\n{len(jumps)} waypoints with a joint step > 0.05 rad", fontsize=9)
        ax.set_xlabel("waypoint")
    axes[0].set_ylabel("joint (deg)")
    axes[1].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.suptitle("UR5: FK of a joint-space segment (100 waypoints, steps <= 0.02 rad), solved back", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "path_traces.png", dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "docs" / "figures")
    a = ap.parse_args(argv)
    a.out.mkdir(parents=True, exist_ok=True)
    branches_figure(a.out)
    path_figure(a.out)


if __name__ == "__main__":
    main()
