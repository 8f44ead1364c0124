"""A suite's pages: ``index.html`` that a roboticist reads in a minute, and its detail pages.

``index.html`` opens with one table -- per arm family (per problem class on an evaluations
board) the solver to use, its success at each rung (target) and its median time, computed by
:mod:`fkopt.kinbench.advice` from the board's own tables -- then the summary per solver (README's
table), a figure beside them, under a table of contents of in-page links; then the figures, every
entry's settings, the machine and its load, and links to the detail pages. The per-arm tables
(``arms.html``) and the rankings of every scope (``rankings.html``, per-problem tables) are pages
of their own, each kept under :data:`PAGE_LIMIT` bytes: figures are the PNG files beside the
pages, never inlined. Headers are words with units (:func:`fkopt.kinbench.html.words`); the
CSVs keep their column names (each header's tooltip).

Everything here reads the suite's tables, config, ``meta.json`` and ``env.json`` only, so the
pages of a stored folder are made again from its files without running a solver:
:func:`stored_suite` reads a folder back, :func:`regenerate` (``fkopt pages``) rewrites its
figures and pages. A newer board's extra columns and solvers are shown as they come (a column
this module does not know gets its CSV name in words).
"""
from __future__ import annotations

import html
import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd

from fkopt.errors import FkoptError
from fkopt.files import file_names, parse_json, read_stored, read_stored_csv
from fkopt.run.kinds import KINDS
from fkopt.kinbench import html as H
from fkopt.kinbench.runner import SuiteOwn
from fkopt.kinbench.advice import class_advice, family_advice, fk_robots, summarise_board, summarise_throughput
from fkopt.kinbench.clock import entry_of
from fkopt.kinbench.config import SuiteConfig
from fkopt.kinbench.physical import LADDER, rung_label
from fkopt.kinbench.reports import (boards_preamble, ERT_RATIO_NOTE, ert_ratio_sections, leaderboard_columns,
                                    leaderboard_sections, meta, PER_PROBLEM, preamble, robot_columns,
                                    ROBOTS_PREAMBLE, SCALING, scaling_target, split_scope)
from fkopt.registry import solver_entry
from fkopt.run.pipeline import from_dict
from fkopt.run.provenance import environment
from fkopt.run.writers import FIGURE

#: Every page's size in bytes stays below this (issue 37: a page loads in a moment).
PAGE_LIMIT = 500_000
#: Detail pages are filled up to this, leaving room for the page's frame.
_FILL = PAGE_LIMIT - 40_000
INDEX = "index.html"
#: What the CPU column measures beside the time to an answer (the two differ by design at a timeout).
CPU_NOTE = ("CPU time per call: the process's CPU time over the whole call (every thread a package starts), also "
            "past the timeout when a package's call cannot be stopped (one ikpy call); the time to an answer "
            "counts a failure at the timeout. On one core, CPU time far below the call's wall time would show a "
            "run the scheduler distorted (answers.csv.gz has both per call).")


@dataclass
class Section:
    ident: str
    title: str
    body: list[str] = field(default_factory=list)

    def html(self, level: int = 2) -> str:
        return f'<h{level} id="{html.escape(self.ident)}">{html.escape(self.title)}</h{level}>' + "".join(self.body)


def _p(text: str, cls: str | None = None) -> str:
    return f'<p{f" class={cls!r}" if cls else ""}>{html.escape(text)}</p>'


def _link(href: str, text: str) -> str:
    return f'<a href="{html.escape(href)}">{html.escape(text)}</a>'


# -- what the page says about the run -----------------------------------------------------------
def meta_of(sr) -> dict:
    """meta.json's content: the stored one (a folder read back), or what the writer will store."""
    stored = getattr(sr, "meta", None)
    if isinstance(stored, dict):
        return stored
    try:
        return meta(sr)
    except Exception:        # a result without a manifest (a test's stand-in): nothing recorded
        return {}


def env_of(sr) -> dict:
    stored = getattr(sr, "env", None)
    if isinstance(stored, dict):
        return stored
    try:
        return environment()
    except Exception:
        return {}


def load_text(meta: dict) -> str:
    """meta.json's ``load_avg`` ({start, end}: the 1, 5, 15-minute load averages) in words, or
    "not recorded" (boards stored before kinbench recorded it)."""
    load = meta.get("load_avg")
    if not load:
        return "not recorded (this board was stored before kinbench recorded the machine's load)"

    def one(v):
        if isinstance(v, (list, tuple)):
            return " / ".join(f"{float(x):.2f}" for x in v)
        if isinstance(v, dict):
            return ", ".join(f"{k} {one(x)}" for k, x in v.items())
        return f"{float(v):.2f}" if isinstance(v, (int, float)) else str(v)
    if isinstance(load, dict):
        # start before end, whatever order meta.json keeps (read back by fkopt pages, its keys are sorted)
        ordered = sorted(load.items(), key=lambda kv: {"start": 0, "end": 1}.get(kv[0], 2))
        parts = [f"at its {k}: {one(v)}" for k, v in ordered]
        return "load average (1 / 5 / 15 min) " + "; ".join(parts)
    return f"load average {one(load)}"


def machine_section(sr) -> Section:
    env, meta = env_of(sr), meta_of(sr)
    plat, fp = env.get("platform") or {}, env.get("fingerprint") or {}
    lines = [f"Machine: {plat.get('cpu', 'not recorded')} ({plat.get('machine', '?')}, {plat.get('system', '?')}); "
             f"Python {fp.get('python', '?')}, numpy {fp.get('numpy', '?')}, scipy {fp.get('scipy', '?')}, "
             f"BLAS {fp.get('blas_runtime') or fp.get('blas') or '?'}; fkopt {env.get('fkopt_version', '?')} "
             "(env.json).",
             f"Machine load during the run: {load_text(meta)} (meta.json load_avg)."]
    return Section("machine", "Machine and load", [_p(t) for t in lines])


def _settings_text(settings, sep: str = "; ") -> str:
    """An entry's settings, sorted by name: the run writes them in its own order, meta.json read back
    (fkopt pages) in sorted order, and both must write the same page."""
    if isinstance(settings, dict):
        return sep.join(f"{k} = {v}" for k, v in sorted(settings.items()))
    return str(settings)


def documented_settings(name: str) -> str:
    """An entry's settings as its wrapper documents them (from "Settings:" in its module's
    docstring to the end of that paragraph, with the list that follows a paragraph ending in a
    colon; else its class's first paragraph: the organiser's entries), read from fkopt's source
    through the solver registry, or "" when fkopt has no solver of that name."""
    import importlib
    import inspect
    entry = solver_entry(name)
    if entry is None:
        return ""
    paras = []
    for doc in (inspect.getdoc(importlib.import_module(entry.make.__module__)), inspect.getdoc(entry.make)):
        paras = [" ".join(p.split()) for p in (doc or "").split("\n\n")]
        at = next((k for k, p in enumerate(paras) if "Settings:" in p), None)
        if at is not None:
            chosen = paras[at][paras[at].index("Settings:"):]
            if chosen.endswith(":"):         # "... except:" then its list as paragraphs of their own
                for item in paras[at + 1:]:
                    if not item.startswith("* "):
                        break
                    chosen += " " + item
            break
    else:
        chosen = paras[0] if paras else ""
    chosen = re.sub(r":\w+:`~?([^`]+)`", r"\1", chosen)        # Sphinx roles (:func:`x`) as plain names
    return chosen.replace("``", "").replace("`", "")


def clock_settings_section(sr, answers: pd.DataFrame | None, throughput: pd.DataFrame | None = None) -> Section:
    """Every entry's settings, the clock track's and the throughput track's own (such as
    pytorch-kinematics'): as recorded in meta.json (``entries``: solver -> the settings its wrapper
    ran with) when the board recorded them, beside the wrapper's documented settings and reasons."""
    c, meta = sr.config, meta_of(sr)
    clock, tp = c.tracks.clock, c.tracks.throughput
    rung = H.rung_words(_rung_label(clock.rung))
    body = [_p(f"Clock track: {clock.queries or 'every'} frozen in-limit poses per arm from pose set "
               f"'{clock.set}' of {c.pose_sets}; timeouts {', '.join(f'{t:g}' for t in clock.timeouts_ms)} ms (IK), "
               f"{', '.join(f'{t:g}' for t in clock.fk_timeouts_ms)} ms (FK); times as ratios to {clock.reference} (IK) "
               f"and {clock.fk_reference} (FK) on the same query in the same process; the board's rung {rung}; "
               f"seed {c.seed}." + (f" Throughput track: batches {tp.batches} (FK {tp.fk_batches}), best of "
                                    f"{tp.repeats} calls." if tp is not None else "")),
            _p("Each outside entry's own published protocol and figures, kinbench's reproduction of them on this "
               "machine (or why a figure is not reproduced) and every difference from the package's defaults with its "
               "reason: docs/kinbench.md, \"Outside entries: each as its authors run it\".", "note")]
    recorded = meta.get("entries") if isinstance(meta.get("entries"), dict) else {}
    names = list(dict.fromkeys([clock.reference, *clock.solvers, clock.fk_reference, *clock.fk_solvers]
                               + ([] if answers is None else list(answers["solver"].unique()))))
    batched = [] if tp is None else [n for n in tp.solvers if n not in names]
    if throughput is not None and "solver" in throughput:      # a throughput-only entry the table holds
        batched = [n for n in batched if n in set(throughput["solver"])]
    rows = []
    for name in names + batched:
        if name not in batched and answers is not None and name not in set(answers["solver"]):
            continue
        limit = "not run"
        if name in batched:
            limit = "throughput track only: each batch in one call, no timeout"
        elif answers is not None:
            given = answers.loc[answers["solver"] == name, "given_timeout_ms"]
            limit = ("yes: run once per timeout, stopped by it" if given.notna().any()
                     else "no: run once to its own limits, judged at each timeout")
        st = dict(recorded.get(name) or {})
        package = st.pop("package", None)      # "pytracik 0.0.3": the package column, with its version
        ran = _settings_text(st) if name in recorded else "not recorded with this board"
        documented = documented_settings(name) or "-"
        sub = next((s for s in clock.submissions if s.solver == name), None)
        if sub is not None:
            ran, documented = f"submitted: {sub.description} (machine: {sub.machine})", "the submission (config)"
        known = solver_entry(name)
        rows.append({"solver": name, "entry": entry_of(name),
                     "package": package or (known.package if known is not None else "-"),
                     "wall-clock limit": limit, "recorded": ran, "documented": documented})
    cols = ["solver", "entry", "package", "wall-clock limit", "recorded", "documented"]
    body.append(H.table_html(pd.DataFrame(rows), cols, "settings-table",
                             labels={"wall-clock limit": "wall-clock limit",
                                     "recorded": "settings the board ran with (meta.json entries)",
                                     "documented": "settings and reasons as the wrapper documents them"}))
    return Section("settings", "Settings of every entry", body)


def suite_settings_section(sr) -> Section:
    """Every solver of an evaluations board with its settings (the stored config's)."""
    c = sr.config
    rows = []
    for s in c.solvers:
        sub = c.subset_of(s.key)
        params = _settings_text(s.params or {}, ", ") or "defaults"
        rows.append({"solver": s.key, "track": s.track, "method": s.name, "settings": params,
                     "population": "default" if s.population is None else s.population,
                     "iterations": "from the budget" if s.iterations is None else s.iterations,
                     "runs per pose": c.runs_of(s.key), "board": sub.name if sub is not None else "full"})
    for o in c.outside:
        rows.append({"solver": o.solver, "track": o.track, "method": "outside results", "settings": o.description or "-",
                     "population": "-", "iterations": "-", "runs per pose": "-", "board": "full"})
    cols = ["solver", "track", "method", "settings", "population", "iterations", "runs per pose", "board"]
    body = [_p(preamble(c))] + ([_p(boards_preamble(c))] if c.subsets else [])
    body.append(H.table_html(pd.DataFrame(rows), cols, "settings-table", labels={k: k for k in cols}))
    return Section("settings", "Settings of every entry", body)


def throughput_section(throughput: pd.DataFrame | None) -> Section | None:
    """The throughput track on the page: per solver and batch size, queries per second beside the
    reference's one-query calls, over the arms (:func:`fkopt.kinbench.advice.summarise_throughput`);
    None when the board has no throughput table."""
    if throughput is None or throughput.empty:
        return None
    table = summarise_throughput(throughput)
    success = [col for col in table.columns if col.startswith("success_")]
    note = ("Batched calls: each solver answers b queries in one call (best of the track's repeats), beside the "
            "reference answering them one call each, timed right after on the same queries; median over the arms "
            "of queries per second and of the ratio, success (kinbench's FK) mean over the arms. Every core "
            "allowed (the clock track is one core). An entry that takes batches only (such as "
            "pytorch-kinematics) is on this track alone.")
    return Section("throughput", "Throughput (batched calls)", [
        _p(note, "note"),
        H.table_html(table, ["solver", "entry", "reference", "batch", "arms", "queries_per_s",
                             "reference_queries_per_s", "ratio", *success], "throughput-table", shares=False,
                     labels={"batch": "queries per call", "arms": "arms", "reference": "reference (one query per call)",
                             "queries_per_s": "queries per second (median over arms)",
                             "reference_queries_per_s": "reference's queries per second (median over arms)",
                             "ratio": "ratio of the rates (median over arms)"})])


def _rung_label(rung: int) -> str:
    return rung_label(LADDER[rung])


# -- the opening tables --------------------------------------------------------------------------
def _families(c) -> dict[str, str]:
    return {p.name: p.problem_class for p in c.problems}


def robots_lead(sr, board: pd.DataFrame) -> tuple[Section, Section, str]:
    """(which solver per arm family, summary per solver, the lead figure's file name)."""
    clock = sr.config.tracks.clock
    fam = family_advice(board, _families(sr.config))
    success = [col for col in board.columns if col.startswith("success_")]
    extra = ["cpu_ms_median"] if "cpu_ms_median" in fam else []
    rung = H.rung_words(str(board["rung"].iloc[0]))
    advice = Section("advice", "Which solver for my arm", [
        _p(f"Among the entries that take every arm of the family: best success at {rung} (mean over the family's "
           "arms), then median time ratio; answers checked by kinbench's FK, a failure counted at the timeout.",
           "note"),
        H.table_html(fam.assign(n_arms=fam["arms"].str.count(",") + 1),
                     ["family", "n_arms", "solver", "timeout_ms", *success, "median_ms", *extra, "median_ratio",
                      *(["leads_where_it_applies"] if "leads_where_it_applies" in fam else [])],
                     "advice-table", shares=False, labels={"n_arms": "arms", "family": "arm family (joints)",
                                                     "leads_where_it_applies": "leads on the arms it takes",
                                                     "median_ratio": f"median time ratio to {clock.reference} "
                                                                     f"(FK: {clock.fk_reference})"}),
        "<details><summary>arms of each family</summary>" + "".join(
            _p(f"{r.family}: {r.arms}", "note") for r in fam.itertuples()) + "</details>"])
    ik_timeouts = sorted(board.loc[~board["robot"].isin(fk_robots(board)), "timeout_ms"].unique())
    fk_only = not ik_timeouts            # a board of parallel mechanisms only: its FK rows are the summary
    t = float(ik_timeouts[-1]) if ik_timeouts else float(board["timeout_ms"].max())
    summary = summarise_board(board, t, fk=fk_only)
    cols = ["solver", "entry", "arms", *success, "worst_arm", "median_ms",
            *(["cpu_ms_median"] if "cpu_ms_median" in summary else []), "median_ratio"]
    note = (f"FK at a {t:g} ms timeout, success mean over the mechanisms an entry ran." if fk_only else
            f"IK at a {t:g} ms timeout, success mean over the arms an entry ran (README's table).")
    if "cpu_ms_median" in summary:
        note += " " + CPU_NOTE
    body = [_p(note, "note"),
            H.table_html(summary, cols, "summary-table", shares=False,
                         labels={"median_ratio": f"median time ratio to {clock.reference}"})]
    fk = [r for r in board["robot"].unique() if r in fk_robots(board)]
    if fk:
        tf = float(board.loc[board["robot"].isin(fk), "timeout_ms"].max())
        fks = summarise_board(board, tf, fk=True)
        body += [_p(f"FK of the parallel mechanisms ({', '.join(fk)}) at {tf:g} ms, success at the generating pose; "
                    f"ratios to {clock.fk_reference}.", "note"),
                 H.table_html(fks, [c for c in cols if c in fks], "summary-fk-table", shares=False,
                              labels={"median_ratio": f"median time ratio to {clock.fk_reference}"})]
    return advice, Section("summary", "Summary per solver", body), "clock_all.png"


def _targets(c) -> list[str]:
    return [f"{t:.0e}" for t in c.targets]


def evaluations_lead(sr, tables: dict) -> tuple[Section, Section, str]:
    """(which solver per problem class, summary per solver, the lead figure's file name) of an
    evaluations board."""
    c = sr.config
    targets = _targets(c)
    target = "1e-06" if "1e-06" in targets else f"{scaling_target(c.targets):.0e}"   # advice_table's, docs/robots.md
    advice_cols = None
    runs, timing = tables.get("runs.csv"), tables.get("timing.csv")
    body = []
    if runs is not None and timing is not None and not runs.empty:
        adv = class_advice(runs, timing, targets, target)
        advice_cols = ["class", "problems", "solver", *[f"success_{t}" for t in targets], "ms_per_solve", "candidates"]
        body = [_p(f"Among the solvers run on every problem of the class: best success at fitness {H.number(target)} "
                   "(mean over the class's problems), then median time per solve.", "note"),
                H.table_html(adv, advice_cols, "advice-table", labels={"candidates": "solvers compared",
                                                                "problems": "problems"})]
    else:
        body = [_p("No runs stored: nothing to advise.")]
    advice = Section("advice", "Which solver for which problem class", body)
    lb = tables["leaderboard.csv"]
    owner = {}
    for board, solvers in (c.board_cells() if c.subsets else [(None, [s.key for s in c.solvers])]):
        for s in solvers:
            owner.setdefault(s, board)
    rows = []
    for scope, g in lb.groupby("scope", sort=False):
        board, within = split_scope(scope)
        if not within.startswith("track:"):
            continue
        for r in g.to_dict("records"):
            if owner.get(r["solver"], board) == board or r["solver"] not in owner:
                rows.append({"board": board or "", **r})
    summary = pd.DataFrame(rows).drop_duplicates("solver") if rows else lb.iloc[:0]
    success = [col for col in lb.columns if col.startswith("success_")]
    cols = (["board"] if c.subsets else []) + ["solver", "track", "rank", "score", "ci_low", "ci_high", *success]
    text = ("Each solver ranked within its track" + (" on its board (the cells its subset ran)" if c.subsets else "")
            + "; success: share of (problem, set, pose, run) reaching each target.")
    figure = "ecdf_all.png"
    if c.subsets:
        first = c.board_cells()[0][0]
        figure = f"ecdf_{first}_all.png"
    return advice, Section("summary", "Summary per solver", [_p(text, "note"), H.table_html(summary, cols, "summary-table")]), figure


# -- detail pages ---------------------------------------------------------------------------------
def pack(stem: str, sections: list[Section], limit: int = _FILL) -> list[tuple[str, list[Section]]]:
    """Sections onto pages ``stem.html``, ``stem-2.html``, ... each under ``limit`` bytes."""
    pages, current, size = [], [], 0
    for s in sections:
        n = len(s.html(3).encode("utf-8"))
        if current and size + n > limit:
            pages.append(current)
            current, size = [], 0
        current.append(s)
        size += n
    if current:
        pages.append(current)
    return [(f"{stem}.html" if k == 0 else f"{stem}-{k + 1}.html", p) for k, p in enumerate(pages)]


def detail_page(folder: Path, name: str, title: str, intro: str, sections: list[Section]) -> str:
    body = [f"<h1>{html.escape(title)}</h1>", f"<p>{_link(INDEX, 'back to the board')}. {html.escape(intro)}</p>",
            H.toc([(s.ident, s.title) for s in sections])] + [s.html(2) for s in sections]
    text = H.page(title, body)
    (folder / name).write_text(text, encoding="utf-8")
    return name


def arm_sections(sr, folder: Path, board: pd.DataFrame) -> list[Section]:
    fam = _families(sr.config)
    stems = file_names(board["robot"].unique(), reserved=("all",))
    ids = file_names(board["robot"].unique(), allowed="A-Za-z0-9_-")
    cols = robot_columns(board)
    known = set(cols) | {"reference", "rung", "source", "throughput_batch", "throughput_ratio", "queries",
                         "time_ms_p95", "reference_ms_median"}
    cols = cols + [c for c in ("cpu_ms_median", "other_mode", "time_ms_p95") if c in board and c not in cols]
    cols += [c for c in board.columns if c not in known and c not in cols]      # a newer board's columns
    out = []
    for robot, g in board.groupby("robot", sort=False):
        shown = [c for c in cols if c in g and c != "robot" and not (c == "other_mode" and g[c].isna().all())]
        body = [_p(f"Family {fam.get(robot, '?')}; reference {g['reference'].iloc[0]}, its median "
                   f"{g['reference_ms_median'].iloc[0]:.3g} ms here.", "note"),
                H.table_html(g, shown, f"arm-table-{ids[robot]}", reference=str(g["reference"].iloc[0]))]
        png = folder / f"clock_{stems[robot]}.png"
        if png.exists():
            body.append(H.img(png, f"{robot}: share of queries answered at the board's rung against the time (ms)"))
        out.append(Section(f"arm-{ids[robot]}", robot, body))
    return out


def ranking_sections(sr, tables: dict) -> list[Section]:
    """Every scope's ranking, the ERT ratios, the scaling tables and (suites without boards)
    the per-problem tables."""
    c = sr.config
    lb = tables["leaderboard.csv"]
    cols = leaderboard_columns(lb)
    out = []
    for k, (scope, g) in enumerate(leaderboard_sections(tables)):
        out.append(Section(f"lb-{k}", f"Ranking {scope}", [H.table_html(g, cols, "leaderboard" if k == 0 else f"lb-t{k}")]))
    for k, (scope, g) in enumerate(ert_ratio_sections(tables)):
        out.append(Section(f"er-{k}", f"ERT ratio {scope}", [_p(ERT_RATIO_NOTE, "note") if k == 0 else "",
                                                             H.table_html(g, list(g.columns), f"er-t{k}")]))
    sc = tables.get("scaling.csv")
    if sc is not None:
        target = scaling_target(c.targets)
        by = ["board", "class"] if "board" in sc.columns else "class"
        for k, (cls, g) in enumerate(sc[np.isclose(sc["target"], target)].groupby(by, sort=True)):
            name = "/".join(cls) if isinstance(cls, tuple) else cls
            out.append(Section(f"sc-{k}", f"Cost against dimension {name} (target {H.number(f'{target:g}')})",
                               [H.table_html(g, SCALING, f"sc-t{k}")]))
    ms = tables.get("measures.csv")
    if ms is not None and "board" not in ms.columns:
        for k, (problem, g) in enumerate(ms.groupby("problem", sort=False)):
            out.append(Section(f"pp-{k}", f"Problem {problem}", [H.table_html(g, PER_PROBLEM, f"pp-t{k}")]))
    return out


# -- the pages -------------------------------------------------------------------------------------
def write_pages(sr, folder: Path, tables: dict) -> list[str]:
    """index.html and its detail pages (the names written)."""
    lb = tables.get("leaderboard.csv")
    if lb is None:
        return []
    folder = Path(folder)
    c = sr.config
    robots = tables.get("leaderboard-robots.csv")
    answers = tables.get("answers.csv.gz")
    written = []
    details: list[Section] = []
    if robots is not None and not robots.empty:
        advice, summary, lead_png = robots_lead(sr, robots)
        arms = pack("arms", arm_sections(sr, folder, robots))
        written += [detail_page(folder, name, f"{c.name}: every arm on the clock",
                                "Per arm: every entry at every timeout (the rows of leaderboard-robots.csv), and "
                                "its figure. " + ROBOTS_PREAMBLE
                                + (" " + CPU_NOTE if "cpu_ms_median" in robots else ""), secs) for name, secs in arms]
        links = [f"{_link(f'{name}#{s.ident}', s.title)}" for name, secs in arms for s in secs]
        details.append(Section("arms", "Per arm", [_p("Every entry at every timeout on each arm, with its figure:", "note"),
                                                   "<p>" + " · ".join(links) + "</p>"]))
        settings = clock_settings_section(sr, answers, tables.get("throughput.csv"))
        figures = [folder / "clock_all.png"] + sorted(p for p in folder.glob("ecdf_*.png"))
    else:
        advice, summary, lead_png = evaluations_lead(sr, tables)
        settings = suite_settings_section(sr)
        figures = sorted(folder.glob("ecdf_*.png")) + sorted(folder.glob("scaling_*.png"))
    ms = tables.get("measures.csv")
    ranks = pack("rankings", ranking_sections(sr, tables))
    with_problems = ms is not None and "board" not in ms.columns
    written += [detail_page(folder, name, f"{c.name}: every ranking", "Each scope's ranking (leaderboard.csv), the ERT "
                            "ratios and the cost against dimension" + (", the per-problem tables" if with_problems else "")
                            + ".", secs) for name, secs in ranks]
    per_problem = ("" if ms is None or "board" not in ms.columns else
                   " The per-problem tables of every board (success rate and ERT per problem, set, solver and "
                   "target) are measures.csv and leaderboard.md: as a page they would be megabytes.")
    details.append(Section("rankings", "Every ranking", [_p("Rankings of every board, track and class, ERT ratios and "
                                                           "tables of the cost against dimension:" + per_problem, "note"),
                                                        "<p>" + " · ".join(_link(name, f"{name} ({len(secs)} tables)")
                                                                           for name, secs in ranks) + "</p>"]))
    lead_path = folder / lead_png
    shown = [p for p in figures if p.exists() and p.name != lead_png]
    figs = Section("figures", "Figures", [_p("Each figure is the PNG beside this page (a PDF twin beside it).", "note"),
                                          '<div class="figs">' + "".join(H.img(p) for p in shown) + "</div>"])
    # meta.json and env.json are written after the pages when fkopt suite runs: named all the same
    files = sorted({p.name for p in folder.iterdir() if p.suffix in (".csv", ".gz", ".md")} | {"meta.json", "env.json"})
    files_sec = Section("files", "Files", [_p("The tables behind this page (column names as in the CSVs):", "note"),
                                          "<p>" + " · ".join(_link(f, f) for f in files) + "</p>"])
    machine = machine_section(sr)
    rates = throughput_section(tables.get("throughput.csv")) if robots is not None and not robots.empty else None
    sections = [advice, summary, figs, *([rates] if rates is not None else []), settings, machine, *details, files_sec]
    caption = ("Every IK arm pooled; each arm's on the Per arm page." if robots is not None and not robots.empty
               else "Every problem of the first board.")
    lead_fig = H.img(lead_path, caption, lazy=False) if lead_path.exists() else ""
    body = [f"<h1>{html.escape(c.title or c.name)}</h1>",
            H.toc([(s.ident, s.title) for s in sections]),
            f'<div class="lead"><div>{advice.html()}</div>{lead_fig}</div>', summary.html()]
    body += [s.html() for s in sections[2:]]
    body.append(_p("Click a column header to sort; hover a header for its CSV column.", "note"))
    (folder / INDEX).write_text(H.page(f"{c.name} leaderboard", body), encoding="utf-8")
    stale = {p.name for p in folder.glob("*.html")} - {INDEX, *written}
    for name in stale:                     # a detail page an earlier, larger board needed
        (folder / name).unlink()
    return [INDEX, *written]


# -- a stored folder, read back --------------------------------------------------------------------
def stored_suite(folder: str | Path):
    """(result, tables) of a stored suite folder: its config (meta.json), meta.json and env.json,
    and every table file it holds, read back -- what the figures and pages are made of."""
    OUTPUTS = KINDS["suite"].outputs        # the suite kind's files (registered by fkopt.kinbench)
    folder = Path(folder)
    where = folder / "meta.json"
    if not where.is_file():
        raise FkoptError(f"{where}: no meta.json (not a stored results folder)")
    meta = parse_json(read_stored(folder, "meta.json"), str(where))
    if not isinstance(meta, dict) or meta.get("kind") != "suite":
        raise FkoptError(f"{where}: kind: {meta.get('kind') if isinstance(meta, dict) else None!r} "
                         "(allowed: suite; pages are a kinbench suite's)")
    config = from_dict(meta.get("config") or {}, f"{where}: config")
    if not isinstance(config, SuiteConfig):
        raise FkoptError(f"{where}: config: not a suite's")
    try:
        env = parse_json(read_stored(folder, "env.json"), str(folder / "env.json"))
    except (OSError, ValueError, FkoptError):
        env = {}
    text = {"problem": str, "solver": str, "robot": str, "scope": str, "set": str, "class": str, "board": str,
            "track": str, "better_than": str}
    tables = {}
    for out in OUTPUTS:
        path = folder / out.file
        if out.role != FIGURE and path.is_file():
            try:
                df = read_stored_csv(folder, out.file, dtype={k: v for k, v in text.items()}, keep_default_na=True)
            except (OSError, ValueError, pd.errors.ParserError) as err:
                raise FkoptError(f"{path}: not a readable table ({err})") from None
            if "better_than" in df:
                df["better_than"] = df["better_than"].fillna("")
            tables[out.file] = df
    own = SuiteOwn(files=folder, answers=tables.get("answers.csv.gz"), throughput=tables.get("throughput.csv"))
    sr = SimpleNamespace(config=config, meta=meta, env=env if isinstance(env, dict) else {},
                         record=tables.get("runs.csv"), own=own, source=meta.get("config_file"))
    return sr, tables


def regenerate(folder: str | Path, figures: bool = True) -> list[str]:
    """Rewrite a stored suite folder's figures (``figures``) and pages from its stored tables;
    no solver runs, no table is written. Returns the names written."""
    OUTPUTS = KINDS["suite"].outputs        # the suite kind's files (registered by fkopt.kinbench)
    folder = Path(folder)
    sr, tables = stored_suite(folder)
    written = []
    for out in OUTPUTS:
        if out.role != FIGURE or out.file in ("leaderboard.md", INDEX):
            continue
        if figures and sr.record is not None:
            written += out.make(sr, folder, tables)
    return written + write_pages(sr, folder, tables)


def suite_folders(root: str | Path) -> list[Path]:
    """The stored suite folders under ``root`` (``root`` itself when it is one)."""
    root = Path(root)
    if not root.exists():
        raise FkoptError(f"{root}: no such folder")
    candidates = [root] if (root / "meta.json").is_file() else sorted(p.parent for p in root.rglob("meta.json"))
    out = []
    for folder in candidates:
        try:
            kind = json.loads((folder / "meta.json").read_text(encoding="utf-8")).get("kind")
        except (OSError, ValueError, AttributeError):
            kind = None
        if kind == "suite":
            out.append(folder)
        elif folder == root:
            raise FkoptError(f"{folder / 'meta.json'}: kind: {kind!r} (allowed: suite; pages are a kinbench suite's)")
    return out


def html_page(sr, folder: Path, tables: dict) -> list[str]:
    """index.html and its detail pages (:mod:`fkopt.kinbench.pages`): which solver per arm family
    or problem class, the summary per solver, the figures, every entry's settings, the machine's
    load; per-arm tables and every ranking on pages of their own."""
    return write_pages(sr, folder, tables)
