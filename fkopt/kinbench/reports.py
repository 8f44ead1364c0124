"""The files of a suite's results folder (listed in :data:`fkopt.outputs.OUTPUTS` ``"suite"``).

Tables come from :mod:`fkopt.kinbench.measures`; this module only shapes and draws them:
runs.csv, measures.csv (per problem), ecdf.csv, leaderboard.csv, timing.csv, the ECDF figures
(COCO style, PNG + PDF), leaderboard.md and index.html (:mod:`fkopt.kinbench.html`).
"""
from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

import numpy as np
import pandas as pd

from .. import record
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


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.+-]+", "_", text).strip("_")


def ecdf_figures(sr, folder: Path, tables: dict) -> list[str]:
    """One ECDF figure per scope (all problems, each class): the share of (problem, pose,
    target, run) reached against log10(evaluations / dimension), one step line per solver,
    named at its right end as COCO does; tracks told apart by line style."""
    from ..experiment.plotting import plt, save
    df = tables.get("ecdf.csv")
    if df is None or df.empty:
        return []
    pyplot = plt()
    styles = {"black-box": "-", "jacobian": "--", "exact": ":"}
    names = []
    targets = ", ".join(f"{t:.0e}" for t in sr.config.targets)
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
        ax.legend(loc="upper left", fontsize=7)
        stem = "ecdf_all" if scope == "all" else f"ecdf_{_slug(scope.split(':', 1)[1])}"
        names += save(fig, folder / f"{stem}.png")
        pyplot.close(fig)
    return names


def _md_table(df: pd.DataFrame, cols: list[str]) -> str:
    def fmt(v):
        if isinstance(v, float):
            return "inf" if np.isinf(v) else f"{v:.4g}"
        return str(v)
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
    out = [f"# {c.title or c.name}", "", preamble(c), ""]
    for title, pred in (("Overall", lambda s: s == "overall"), ("Per track", lambda s: s.startswith("track:")),
                        ("Per problem class", lambda s: s.startswith("class:"))):
        out += [f"## {title}", ""]
        for scope, g in leaderboard_sections(tables):
            if pred(scope):
                out += [f"### {scope}", "", _md_table(g, cols), ""]
    ms = tables.get("measures.csv")
    if ms is not None:
        out += ["## Per problem", "", "Success rate and ERT (evaluations) per set and target.", ""]
        for problem, g in ms.groupby("problem", sort=False):
            out += [f"### {problem}", "", _md_table(g, PER_PROBLEM), ""]
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
