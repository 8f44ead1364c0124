"""The figures of docs/robots.md's kinbench tracks (all-solutions, paths), drawn from the stored suite
``results/kinbench/kinbench-v3-solutions/`` (``fkopt suite configs/suites/kinbench-v3-solutions.yaml
--out results``), not from a new run:

* ``docs/figures/tracks_all_solutions.png`` -- per arm, each entry's recall of EAIK's analytic set and of
  the union of every entry's verified answers (bars), its median time per pose as a ratio to fkopt's
  written above;
* ``docs/figures/tracks_paths.png`` -- one frozen path of the paths track (the first where a seeded
  entry fails), each entry's joint traces side by side, the waypoints with a joint step above the
  track's bound (0.05 rad) or an answer off its target marked.

    PYTHONPATH=. python examples/branch_tracks_figures.py [--results results] [--out docs/figures]
"""
from __future__ import annotations

import argparse
import math
import json
from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.kinbench.paths import BOUND, TOL, path_success

ROOT = Path(__file__).resolve().parents[1]


def recall_figure(folder: Path, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    b = pd.read_csv(folder / "leaderboard-solutions.csv")
    # the joint each 7-joint arm has locked, as the stored suite's config says
    locked = json.loads((folder / "meta.json").read_text())["config"]["tracks"]["all-solutions"].get("locked", {})
    arms = list(dict.fromkeys(b["problem"]))
    solvers = list(dict.fromkeys(b["solver"]))
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.2), sharey=True)
    w = 0.8 / len(solvers)
    for ax, col, title in ((axes[0], "recall_analytic", "recall of EAIK's analytic set"),
                           (axes[1], "recall_union", "recall of the union of every entry's verified answers")):
        for j, s in enumerate(solvers):
            r = b[b["solver"] == s].set_index("problem").reindex(arms)
            x = np.arange(len(arms)) + (j - (len(solvers) - 1) / 2) * w
            ax.bar(x, 100 * r[col].to_numpy(float), w, label=s)
            if col == "recall_union":
                for xi, v, t in zip(x, 100 * r[col].to_numpy(float), r["time_ratio_median"].to_numpy(float)):
                    if np.isfinite(v):
                        ax.text(xi, v + 1, f"{t:.2g}x", ha="center", va="bottom", fontsize=6, rotation=90)
        ax.set_xticks(np.arange(len(arms)), [a + (f" ({locked[a]} locked)" if a in locked else "") for a in arms],
                      rotation=30, ha="right", fontsize=8)
        ax.set_title(title, fontsize=9)
        ax.set_ylim(0, 118)
    axes[0].set_ylabel("% of the reference set's solutions held")
    fig.legend(*axes[1].get_legend_handles_labels(), fontsize=7, loc="lower center", ncol=len(solvers),
               frameon=False)   # below the axes: inside, it covered the last arms' bars
    fig.suptitle("kinbench all-solutions track: every IK solution of a pose (numbers on the right: median time "
                 "per pose / fkopt's; the restart entries get fkopt's median time)", fontsize=9)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fig.savefig(out / "tracks_all_solutions.png", dpi=110)
    plt.close(fig)


def path_figure(folder: Path, out: Path, problem: str = "ur5") -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    a = pd.read_csv(folder / "paths.csv.gz")
    a = a[a["problem"] == problem]
    solvers = list(dict.fromkeys(a["solver"]))
    failing = [k for k, g in a.groupby("path", sort=True)
               if any(not path_success(h) for _, h in g.groupby("solver", sort=False))]
    k = failing[0] if failing else int(a["path"].min())
    qcols = [c for c in a.columns if c.startswith("q") and c[1:].isdigit() and a[c].notna().any()]   # this arm's joints
    fig, axes = plt.subplots(1, len(solvers), figsize=(4.3 * len(solvers), 3.8), sharey=True)
    for ax, s in zip(np.atleast_1d(axes), solvers):
        g = a[(a["solver"] == s) & (a["path"] == k)].sort_values("waypoint")
        J = g[qcols].to_numpy(float)
        for j in range(J.shape[1]):
            ax.plot(g["waypoint"], J[:, j], lw=1.5, ls="-" if j % 2 == 0 else "--", label=f"joint {j + 1}")  # overlaps seen
        bad = (g["step_rad"] > BOUND) | (g["position_m"] > TOL[0]) | (g["rotation_rad"] > TOL[1]) | ~g["in_limits"]
        for wp in g["waypoint"][bad.to_numpy()]:
            ax.axvline(wp, color="tab:red", lw=0.6, alpha=0.5)
        ok = "succeeds" if path_success(g) else "fails"
        ax.set_title(f"{s}: {ok}\n{int(bad.sum())} waypoints off target or stepping > {BOUND} rad "
                     f"(largest step {math.degrees(g['step_rad'].max()):.1f} deg)", fontsize=8)
        ax.set_xlabel("waypoint")
    np.atleast_1d(axes)[0].set_ylabel("joint (deg)")
    np.atleast_1d(axes)[-1].legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.suptitle(f"kinbench paths track, {problem} path {k}: FK of a joint-space segment (100 waypoints, steps "
                 "<= 0.02 rad) solved back by each entry (red: waypoints that break the path)", fontsize=9)
    fig.tight_layout()
    fig.savefig(out / "tracks_paths.png", dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", type=Path, default=ROOT / "results")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures")
    a = ap.parse_args(argv)
    folder = a.results / "kinbench" / "kinbench-v3-solutions"
    a.out.mkdir(parents=True, exist_ok=True)
    recall_figure(folder, a.out)
    path_figure(folder, a.out)


if __name__ == "__main__":
    main()
