"""The files of a suite's results folder (listed in :data:`fkopt.outputs.OUTPUTS` ``"suite"``).

Tables come from :mod:`fkopt.kinbench.measures`; this module only shapes and draws them:
runs.csv, measures.csv (per problem), ecdf.csv, leaderboard.csv, timing.csv, the ECDF figures
(COCO style, PNG + PDF), leaderboard.md and index.html (:mod:`fkopt.kinbench.html`).
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pandas as pd

from .. import record
from ..files import file_names, md_text
from . import measures as M
from .outside import digest


def runs_table(sr) -> pd.DataFrame:
    """One row per run: the run record's (:func:`fkopt.record.runs_table`)."""
    return record.runs_table(sr.record)


def measures_table(sr) -> pd.DataFrame:
    return M.measures_table(sr.runs, sr.config.targets)


def ecdf_table(sr) -> pd.DataFrame:
    return M.ecdf_table(sr.runs, sr.config.targets, sr.config.budget_per_dim)


def leaderboard_table(sr) -> pd.DataFrame:
    c = sr.config
    return M.leaderboard_table(sr.runs, c.targets, c.budget_per_dim, bootstrap=c.bootstrap, alpha=c.alpha,
                               seed=c.seed)


def timing_table(sr) -> pd.DataFrame:
    """Per (problem, solver): the batched solve's wall time over its (pose, run) rows (the one
    timing writer, :func:`fkopt.record.timing_table`)."""
    settings = {(p, s): {"runs": int(g["runs"].sum()), "total_s": float(g["seconds"].sum())}
                for (p, s), g in sr.timing.groupby(["problem", "solver"], sort=False)}
    return record.timing_table(sr.timing, settings, by=("problem", "solver"))


def scaling_table(sr) -> pd.DataFrame | None:
    return M.scaling_table(sr.runs, sr.config.targets)


def scaling_target(targets) -> float:
    """The target the scaling figure and section show: the middle of the ladder (1e-6 of v1-v3's)."""
    return sorted(targets, reverse=True)[len(targets) // 2]


def ecdf_figures(sr, folder: Path, tables: dict) -> list[str]:
    """One ECDF figure per scope (all problems, each class): the share of (problem, pose,
    target, run) reached against log10(evaluations / dimension), one step line per solver,
    named at its right end as COCO does; tracks told apart by line style."""
    from ..experiment.plotting import legend_off_data, plt, save
    df = tables.get("ecdf.csv")
    if df is None or df.empty:
        return []
    pyplot = plt()
    styles = {"black-box": "-", "jacobian": "--", "exact": ":"}
    names = []
    targets = ", ".join(f"{t:.0e}" for t in sr.config.targets)
    # one file per scope: a class "all" does not overwrite ecdf_all, "a b" and "a_b" differ
    scopes = [s for s in df["scope"].unique() if s != "all"]
    stems = file_names((s.removeprefix("class:") for s in scopes), reserved=("all",))
    for scope, g in df.groupby("scope", sort=False):
        fig, ax = pyplot.subplots(figsize=(5.2, 3.6))
        top = float(sr.config.budget_per_dim)
        for (solver, track), s in g.groupby(["solver", "track"], sort=False):
            s = s.dropna(subset=["evals_per_dim"])      # a solver that reached nothing: flat at 0
            b = np.concatenate([[1.0], np.maximum(s["evals_per_dim"].to_numpy(), 1.0), [top]])
            f = np.concatenate([[0.0], s["fraction"].to_numpy(), [s["fraction"].max() if len(s) else 0.0]])
            x, y = np.log10(b), f
            line, = ax.step(x, y, where="post", linestyle=styles.get(track, "-"), label=f"{solver} ({track})")
            ax.annotate(solver, (x[-1], y[-1]), xytext=(3, 0), textcoords="offset points", fontsize=7,
                        color=line.get_color(), va="center")
        ax.set_xlabel("log10(evaluations / dimension)")
        ax.set_ylabel("fraction of (problem, pose, target, run)")
        ax.set_ylim(-0.02, 1.02)
        what = "all problems" if scope == "all" else scope.split(":", 1)[1]
        ax.set_title(f"{sr.config.name}: {what}; targets {targets}", fontsize=8)
        legend_off_data(ax, fontsize=7)
        stem = "ecdf_all" if scope == "all" else f"ecdf_{stems[scope.removeprefix('class:')]}"
        names += save(fig, folder / f"{stem}.png")
        pyplot.close(fig)
    return names


def scaling_figures(sr, folder: Path, tables: dict) -> list[str]:
    """One figure per class of several dimensions (scaling.csv): log10(ERT / dimension) at the
    middle target against the dimension, one line per solver; a dimension no run of a solver
    solved is left out of its line (ERT infinite), as COCO's scaling plots do."""
    df = tables.get("scaling.csv")
    if df is None or df.empty:
        return []
    from ..experiment.plotting import legend_off_data, plt, save
    pyplot = plt()
    styles = {"black-box": "-", "jacobian": "--", "exact": ":"}
    target = scaling_target(sr.config.targets)
    names = []
    shown = df[np.isclose(df["target"], target)]
    stems = file_names(shown["class"].unique())       # two distinct classes never share a file
    for cls, g in shown.groupby("class", sort=True):
        fig, ax = pyplot.subplots(figsize=(5.2, 3.6))
        for (solver, track), s in g.groupby(["solver", "track"], sort=False):
            s = s[np.isfinite(s["ert_per_dim"])]
            if len(s):
                ax.plot(s["dim"], np.log10(s["ert_per_dim"]), marker="o", linestyle=styles.get(track, "-"),
                        label=f"{solver} ({track})")
        ax.set_xscale("log")
        ax.minorticks_off()
        dims = sorted(set(g["dim"]))
        ax.set_xticks(dims, [str(d) for d in dims], fontsize=7)
        ax.set_xlabel("dimension (number of joints)")
        ax.set_ylabel(f"log10(ERT / dimension) at {target:.0e}")
        ax.set_title(f"{sr.config.name}: {cls}, cost against dimension", fontsize=8)
        legend_off_data(ax, fontsize=7)
        names += save(fig, folder / f"scaling_{stems[cls]}.png")
        pyplot.close(fig)
    return names


SCALING = ["dim", "solver", "track", "trials", "success_rate", "ert", "ert_per_dim"]


def _md_table(df: pd.DataFrame, cols: list[str]) -> str:
    def fmt(v):
        if isinstance(v, float):
            return "inf" if np.isinf(v) else f"{v:.4g}"
        return md_text(v)        # solver labels, classes, problem names: text of a config file
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    lines += ["| " + " | ".join(fmt(v) for v in row) + " |" for row in df[cols].itertuples(index=False)]
    return "\n".join(lines)


def leaderboard_sections(tables: dict) -> list[tuple[str, pd.DataFrame]]:
    lb = tables["leaderboard.csv"]
    return [(scope, g) for scope, g in lb.groupby("scope", sort=False)]


def leaderboard_columns(lb: pd.DataFrame) -> list[str]:
    return (["rank", "solver", "track", "score", "ci_low", "ci_high", "instances", "better_than"]
            + [col for col in lb.columns if col.startswith("success_")])


def preamble(c) -> str:
    """What a leaderboard is made of and how to read it (leaderboard.md and index.html)."""
    return (f"Pose sets {c.pose_sets}; {len(c.problems)} problems, sets {', '.join(c.sets)}, "
            f"{c.runs} runs per pose, budget {c.budget_per_dim} x dimension evaluations, targets "
            f"{', '.join(f'{t:.0e}' for t in c.targets)}. Score: normalised area under the ECDF "
            f"(0..1, higher is better), 95 % bootstrap CI over instances ({c.bootstrap} resamples); "
            f"better_than: Wilcoxon signed-rank test on the paired instance scores, significant at alpha = {c.alpha} after Holm's correction within the table. "
            "Tracks are ranked separately; 'overall' mixes them for reference only (docs/kinbench.md).")


PER_PROBLEM = ["set", "solver", "track", "target", "trials", "success_rate", "ert"]


def leaderboard_markdown(sr, folder: Path, tables: dict) -> list[str]:
    lb = tables.get("leaderboard.csv")
    if lb is None:
        return []
    c = sr.config
    cols = leaderboard_columns(lb)
    out = [f"# {md_text(c.title or c.name)}", "", md_text(preamble(c)), ""]
    for title, pred in (("Overall", lambda s: s == "overall"), ("Per track", lambda s: s.startswith("track:")),
                        ("Per problem class", lambda s: s.startswith("class:"))):
        out += [f"## {title}", ""]
        for scope, g in leaderboard_sections(tables):
            if pred(scope):
                out += [f"### {md_text(scope)}", "", _md_table(g, cols), ""]
    sc = tables.get("scaling.csv")
    if sc is not None:
        target = scaling_target(c.targets)
        out += ["## Cost against dimension", "", f"ERT (evaluations) and ERT / dimension at target {target:.0e} "
                "over every problem, set and pose of a dimension, for the classes of several dimensions "
                "(scaling.csv has every target).", ""]
        for cls, g in sc[np.isclose(sc["target"], target)].groupby("class", sort=True):
            out += [f"### {md_text(cls)}", "", _md_table(g.sort_values(["solver", "dim"], kind="stable"), SCALING), ""]
    ms = tables.get("measures.csv")
    if ms is not None:
        out += ["## Per problem", "", "Success rate and ERT (evaluations) per set and target.", ""]
        for problem, g in ms.groupby("problem", sort=False):
            out += [f"### {md_text(problem)}", "", _md_table(g, PER_PROBLEM), ""]
    tim = tables.get("timing.csv")
    if tim is not None and not tim.empty:
        out += ["## Wall time per solve", "", "Amortised: the batched solve's wall time over its "
                "(pose, run) rows, in this process's worker; not compared by fkopt check.", "",
                _md_table(tim, ["problem", "solver", "runs", "amortised_ms_per_run"]), ""]
    (folder / "leaderboard.md").write_text("\n".join(out), encoding="utf-8")
    return ["leaderboard.md"]


def html_page(sr, folder: Path, tables: dict) -> list[str]:
    """index.html: the leaderboards (sortable), the ECDF figures inline, the per-problem tables."""
    import html
    from .html import img, page, table_html
    lb = tables.get("leaderboard.csv")
    if lb is None:
        return []
    c = sr.config
    cols = leaderboard_columns(lb)
    body = [f"<h1>{html.escape(c.title or c.name)}</h1>",
            f"<p>{html.escape(preamble(c))} Click a column header to sort.</p>"]
    for k, (scope, g) in enumerate(leaderboard_sections(tables)):
        body += [f"<h2>{html.escape(scope)}</h2>", table_html(g, cols, "leaderboard" if k == 0 else f"lb-{k}")]
    figs = sorted(folder.glob("ecdf_*.png"))
    if figs:
        body += ["<h2>Runtime distributions (ECDF)</h2>"] + [img(p) for p in figs]
    sc = tables.get("scaling.csv")
    if sc is not None:
        target = scaling_target(c.targets)
        body.append(f"<h2>Cost against dimension (target {target:.0e})</h2>")
        body += [img(p) for p in sorted(folder.glob("scaling_*.png"))]
        for k, (cls, g) in enumerate(sc[np.isclose(sc["target"], target)].groupby("class", sort=True)):
            body += [f"<h3>{html.escape(cls)}</h3>", table_html(g, SCALING, f"sc-{k}")]
    ms = tables.get("measures.csv")
    if ms is not None:
        body.append("<h2>Per problem</h2>")
        for k, (problem, g) in enumerate(ms.groupby("problem", sort=False)):
            body += [f"<h3>{html.escape(problem)}</h3>", table_html(g, PER_PROBLEM, f"pp-{k}")]
    (folder / "index.html").write_text(page(f"{c.name} leaderboard", body), encoding="utf-8")
    return ["index.html"]


def meta(sr) -> dict:
    c = sr.config
    manifest = sr.manifest or {}
    canonical = hashlib.sha256(json.dumps(manifest, sort_keys=True).encode()).hexdigest()
    return {"kind": "suite", "name": c.name, "paper": c.paper, "config": c.model_dump(mode="json"),
            "config_file": sr.source,
            "pose_sets": {"version": manifest.get("version"), "manifest_canonical_sha256": canonical},
            "outside": {o.solver: digest(c, o, sr.files) for o in c.outside},
            "measures": "fkopt.kinbench.measures (COCO: success rate, ERT, ECDF; bootstrap ranking, Holm)"}
