"""Generate ``REPORT.md``, ``TIMING.md`` and ``index.csv`` from a results tree.

REPORT.md holds only what the seeds determine (it is byte-identical on a rerun); everything
measured in seconds lives in TIMING.md, which changes on every run. Never edit either by hand:
``fkopt report`` (or ``make reproduce``) rewrites them.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from fkopt.files import inside, md_table
from fkopt.reproduce import PAPERS, paper_module  # noqa: F401 (paper_module re-exported)
from fkopt.reproduce.changes import Snapshot, write_changes
from fkopt.reproduce.claims import CLAIMS_FILE, RULES, TIMING_CLAIMS_FILE, Claim, claims_frame
from fkopt.reproduce.engine import claim_experiments, info, judge_paper
from fkopt.run.timing import TIMING_BUDGET_S, TIMING_MIN_RUNS, TIMING_RUNS
from fkopt.reproduce.store import Experiment, Store
from fkopt.run.kinds import stored_kind

MAX_VALUE_ROWS = 60
#: The id prefix of fkopt's own findings among a paper's claims (not claims of the paper: docs/claims.md).
FKOPT_OWN = "fkopt-"


def _summary_view(exp: Experiment) -> pd.DataFrame:
    s = exp.table("summary")
    many = s["case"].nunique() > 8
    cols = ["case", "algorithm", "method", "population", "iterations", "runs", "median_fitness",
            "mean_fitness", "std_fitness", "best_fitness", "worst_fitness", "success_rate",
            "median_iterations_to_threshold", "median_evaluations_to_threshold", "mean_evaluations"]
    cols += [c for c in s.columns if c.startswith("printed_")]
    cols = [c for c in cols if c in s.columns]
    s = s[cols]
    if many:
        num = [c for c in cols if c not in ("case", "algorithm", "method") and pd.api.types.is_numeric_dtype(s[c])]
        agg = s.groupby(["algorithm", "method"], sort=False)[num].median().reset_index()
        agg.insert(0, "case", f"median over {s['case'].nunique()} cases")
        s = agg
    if s["case"].nunique() == 1:
        s = s.drop(columns=["case"])
    if "runs" in s and (s["runs"] == 1).all():   # one run per case: no spread to show
        s = s.drop(columns=[c for c in ("std_fitness",) if c in s])
    return s.dropna(axis=1, how="all")


def _values_view(exp: Experiment) -> pd.DataFrame | None:
    if not exp.has("values.csv"):
        return None
    v = exp.table("values")
    if len(v) > MAX_VALUE_ROWS:
        return None
    keep = [c for c in v.columns if c not in ("median_run", "best_run_value", "best_run_abs_error")]
    v = v[keep]
    if v["case"].nunique() == 1:
        v = v.drop(columns=["case"])
    return v.dropna(axis=1, how="all")


def experiment_section(exp: Experiment, root: Path) -> str:
    kind = stored_kind(exp.meta)
    if kind is not None and kind.report_section is not None:      # a suite: its leaderboard
        return kind.report_section(exp, root)
    cfg = exp.config
    rel = exp.folder.relative_to(root)
    lines = [f"### {exp.title}", ""]
    src = exp.meta.get("config_file")
    lines.append(f"Results: [`results/{rel}/`]({rel}/)" + (f" · config: `{src}`" if src else "")
                 + f" · seed {cfg['seed']}, {cfg['runs']} runs, population {cfg['population']}, "
                 f"{cfg['iterations']} iterations" + (f", threshold {cfg['threshold']:g}" if cfg.get("threshold") else "")
                 + (" (each run stops there)" if cfg.get("stop_at_threshold") else "")
                 + f", objective `{exp.meta.get('objective')}`.")
    if cfg.get("description"):
        lines += ["", cfg["description"].strip()]
    lines += ["", "Final fitness over all runs (fkopt) beside the paper's printed values (`printed_*`):", "",
              md_table(_summary_view(exp)), ""]
    values = _values_view(exp)
    if values is not None:
        lines += ["Solved variables: the median run (lower median of the final fitness) and the mean "
                  "absolute error over all runs, beside the printed values:", "", md_table(values), ""]
    if exp.has("inputs.csv"):
        lines += ["Inputs given in the file vs fkopt's inverse map of the nominal pose:", "",
                  md_table(exp.table("inputs")), ""]
    extra = getattr(paper_module(exp.paper), "extra_tables", None)
    if extra:
        for caption, df in extra(exp):
            lines += [caption, "", md_table(df), ""]
    for fig in exp.figures():
        if fig.endswith("_time.png"):
            continue   # drawn from timings: shown in TIMING.md
        lines.append(f"![{exp.name} {fig}]({rel}/{fig})")
    lines.append("")
    return "\n".join(lines)


def claims_table(claims: list[Claim]) -> str:
    df = pd.DataFrame([{"id": c.id, "claim": c.text, "verdict": f"**{c.verdict}**", "condition": c.condition,
                        "fkopt's evidence": c.evidence} for c in claims])
    if claims and not any(c.id for c in claims):
        df = df.drop(columns=["id"])
    if claims and not any(c.condition for c in claims):
        df = df.drop(columns=["condition"])
    return df.to_markdown(index=False) if claims else "_(none)_"


def build_report(root: str | Path) -> tuple[str, str, pd.DataFrame]:
    root = Path(root)
    store = Store(root)
    papers = [p for p in PAPERS if store.experiments(p)] + [p for p in store.papers() if p not in PAPERS]
    out = ["# fkopt reproduction report", "",
           "Generated by `fkopt report` from the stored results (never edited by hand). Every table "
           "is fkopt's own run beside the paper's printed numbers. The models (equations, every "
           "reconstruction and its evidence, the papers' known errors) are documented in "
           "[docs/models.md](../docs/models.md). Wall-clock timings and every claim about time are "
           "judged in [TIMING.md](TIMING.md) only (one source of truth), because they change on every "
           "run while everything here is fixed by the seeds. Statistics are over all runs, never a "
           "single lucky run.", "", "**Verdicts.**", ""] + [f"- {r}" for r in RULES] + [
           "- The verdicts of this file are stored in `results/<paper>/claims.csv` (columns id, claim, "
           "verdict, condition); `fkopt check` fails when a recomputed verdict differs. The claims are "
           "data (`configs/<paper>/claims.yaml`) judged by one engine: rules in "
           "[docs/claims.md](../docs/claims.md).",
           "- **ABC population convention:** an ABC's population is its number of food sources (= employed "
           "= onlooker bees), so one ABC iteration costs about 2 x population evaluations, a PSO iteration "
           "population; at the papers' equal iterations ABC gets more evaluations, hence every comparison "
           "at equal evaluations too ([docs/models.md](../docs/models.md)).", "",
           "**Figures** are named after the paper figure they mirror (`fig2.png`, with a PDF twin) and use "
           "the papers' algorithm names and units. A fitness of exactly 0 cannot sit on a log axis: it is "
           "drawn on a grey band labelled \"0 (exact, drawn at floor)\" a decade below the smallest "
           "positive value. Curves show the median of the runs with a quartile band (a single run is drawn "
           "as itself); runs that stop at a threshold end where the median run stopped (a bar); "
           "independent poses are markers, never joined by lines.", ""]
    timing = ["# fkopt timings", "",
              "Generated by `fkopt report`; the single source of every timing claim. **Method:** the "
              "papers' mode, one run at a time: a sample of each task's runs (runs 0..n-1 with "
              f"n = max(1, ceil({TIMING_RUNS} / cases)), on the first {TIMING_RUNS} cases; a task stops "
              f"adding runs after {TIMING_BUDGET_S:g} s of timed runs but times at least {TIMING_MIN_RUNS}) "
              "is solved again alone with the same seed stream and timed around that call (after an "
              "untimed warm-up), the algorithms of a case interleaved (run 0 of each, then run 1 of each: "
              "A B A B ...) in one process, so that a slow period of the machine hits all alike. Tables give the median and quartiles of those runs; `amortised_ms_per_run` "
              "(the batch's wall time / runs) is shown for information and never judged. Two "
              "algorithms' times differ only if a two-sided Mann-Whitney test over the timed runs "
              "rejects equality at alpha = 0.05, otherwise the verdict is *within noise*. Measured on "
              "the machine that ran `make reproduce` last (numpy, one process); the papers' times are "
              "MATLAB/Java on their machines.", ""]
    if (root / "CHANGES.md").is_file():    # written by fkopt reproduce (fkopt.reproduce.changes)
        out += ["**What the last regeneration moved** (files, summary rows old → new, verdicts): "
                "[CHANGES.md](CHANGES.md).", ""]
    out.append("Contents: " + " · ".join(f"[{p}](#{p})" for p in papers))
    out.append("")
    index_rows = []
    for paper in papers:
        about = info(paper)
        judged = judge_paper(paper, store)
        exps = store.experiments(paper)
        order = about["experiments"]
        exps.sort(key=lambda e: (order.index(e.name) if e.name in order else len(order), e.name))
        out += [f"## {paper}", "", f"**{about['title']}**", ""]
        for note in about["notes"]:
            out.append(f"- {note}")
        out.append("")
        if about["inconsistencies"]:
            out += ["### The paper's internal inconsistencies", ""]
            out += [f"- {x}" for x in about["inconsistencies"]] + [""]
        if judged is None and claim_experiments(paper):
            out += ["The paper's claims are judged where the experiments they rest on are stored (the "
                    f"tracked results/REPORT.md: {', '.join(sorted(claim_experiments(paper)))}); this tree holds "
                    "none of them, so it has no verdicts of the paper.", ""]
        if judged is not None:
            cl, tc = judged
            out += ["### Claims", "", claims_table(cl), ""]
            disagree = [c.id or c.text[:40] for c in cl if c.numbers.get("bases_disagree")]
            if disagree:
                out += ["Budget bases disagree (equal iterations vs equal evaluations) for: "
                        + ", ".join(f"`{x}`" for x in disagree) + "; the verdict uses the paper's basis.", ""]
            if tc:
                own = sum(c.id.startswith(FKOPT_OWN) for c in tc)   # fkopt's own tests, never the paper's
                out += [f"The paper's {len(tc) - own} claim(s) about time"
                        + (f" and fkopt's own {own} test(s) (ids `{FKOPT_OWN}*`)" if own else "")
                        + f" are judged in [TIMING.md](TIMING.md#{paper}) only.", ""]

        timing += [f"## {paper}", ""]
        for exp in exps:
            out.append(experiment_section(exp, root))
            t = exp.table("timing")
            timing += [f"### {exp.title}", "", md_table(t), ""]
            if exp.has("cases_time.png"):
                timing.append(f"![{exp.name} time per case]({exp.folder.relative_to(root)}/cases_time.png)\n")
            for fig in exp.figures():
                if fig.endswith("_time.png") and fig != "cases_time.png":
                    timing.append(f"![{exp.name} {fig}]({exp.folder.relative_to(root)}/{fig})\n")
            index_rows += index_rows_of(exp)
        if judged is not None and judged[1]:
            timing += ["### Timing claims", "", claims_table(judged[1]), ""]
    return "\n".join(out).rstrip() + "\n", "\n".join(timing).rstrip() + "\n", pd.DataFrame(index_rows)


def index_rows_of(exp: Experiment) -> list[dict]:
    if not exp.has("summary.csv"):     # a suite (kinbench): its leaderboard is its index
        return []
    s = exp.table("summary")
    rows = []
    for (algo, method), grp in s.groupby(["algorithm", "method"], sort=False):
        row = {"paper": exp.paper, "experiment": exp.name, "title": exp.title, "algorithm": algo,
               "method": method, "cases": grp["case"].nunique(), "runs": int(grp["runs"].iloc[0]),
               "population": int(grp["population"].iloc[0]), "iterations": int(grp["iterations"].iloc[0]),
               "median_fitness": float(grp["median_fitness"].median()),
               "mean_fitness": float(grp["mean_fitness"].mean()),
               "mean_evaluations": float(grp["mean_evaluations"].mean())}
        for col in ("threshold", "success_rate", "median_iterations_to_threshold"):
            if col in grp:
                row[col] = float(grp[col].median()) if col != "success_rate" else float(grp[col].mean())
        rows.append(row)
    return rows


def claims_files(root: str | Path) -> dict[Path, pd.DataFrame]:
    """``<paper>/claims.csv`` of every paper with claims (the verdicts ``fkopt check`` guards) and
    ``<paper>/timing_claims.csv`` (the timing verdicts, which change with the machine)."""
    root = Path(root)
    store = Store(root)
    out = {}
    for paper in store.papers():
        judged = judge_paper(paper, store)
        if judged is not None:
            out[root / paper / CLAIMS_FILE] = claims_frame(judged[0])
            if judged[1]:
                out[root / paper / TIMING_CLAIMS_FILE] = claims_frame(judged[1])
    return out


def draw_paper_figures(root: str | Path) -> list[Path]:
    """Figures of the models alone (e.g. chang2024 Fig. 3), drawn into their experiment's folder."""
    out = []
    for exp in Store(root).experiments():
        draw = getattr(paper_module(exp.paper), "figures", None)
        if draw:
            out += [exp.folder / name for name in draw(exp)]
    return out


@dataclass
class WrittenReport:
    """What :func:`write_report` wrote, and the tree's snapshot CHANGES.md was computed from
    (None without ``changes_since``): ``fkopt reproduce`` judges its agreement line on that same
    snapshot instead of hashing the tree a second time."""

    paths: list[Path]
    after: Snapshot | None = None


def write_report(root: str | Path, changes_since=None) -> WrittenReport:
    """Write REPORT.md, TIMING.md, index.csv and every paper's claims.csv under ``root``;
    with ``changes_since`` (a :class:`~.changes.Snapshot` of the tree before a rerun) also
    CHANGES.md, after the verdicts it compares and before the report that links it.

    Every file is checked before anything is computed or written: it must resolve (symbolic
    links included) inside ``root`` (:func:`fkopt.files.inside`), so a link planted in a
    results root cannot make ``fkopt report`` overwrite a file elsewhere."""
    root = Path(root)
    paths = [root / "REPORT.md", root / "TIMING.md", root / "index.csv"]
    claims = [root / paper / name for paper in Store(root).papers() for name in (CLAIMS_FILE, TIMING_CLAIMS_FILE)]
    changes = [root / "CHANGES.md"] if changes_since is not None else []
    for path in paths + claims + changes:
        inside(root, path, "report")
    for exp in Store(root).experiments():     # folders a paper's figures are drawn into
        if getattr(paper_module(exp.paper), "figures", None):
            for path in [exp.folder, *exp.folder.iterdir()]:
                inside(root, path, "report")
    figures = draw_paper_figures(root)
    for path, df in claims_files(root).items():
        df.to_csv(inside(root, path, "report"), index=False)
        paths.append(path)
    after = None
    if changes_since is not None:
        changes_path, after = write_changes(root, changes_since)
        paths.append(changes_path)
    report, timing, index = build_report(root)
    paths[0].write_text(report)
    paths[1].write_text(timing)
    index.to_csv(paths[2], index=False, float_format="%.10g")
    return WrittenReport(paths + figures, after)
