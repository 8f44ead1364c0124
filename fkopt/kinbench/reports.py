"""The files of a suite's results folder (listed in :data:`fkopt.run.writers.OUTPUTS` ``"suite"``).

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

from fkopt.run import record
from fkopt.run import plotting   # matplotlib itself only when plotting.plt() is called (save by module: tests watch it)
from fkopt.run.plotting import legend_off_data, plt
from fkopt.files import file_names, md_table, md_text, read_stored_csv
from fkopt.kinbench import measures as M
from fkopt.kinbench.outside import digest
from fkopt.kinbench.submissions import submission_digest
from fkopt.kinbench.clock import clock_board, rung_success
from fkopt.kinbench.html import rung_words
from fkopt.kinbench.physical import LADDER, rung_label
from fkopt.kinbench.releases import board_version


BOARD_PREFIX = "board:"


def suite_boards(sr) -> list[tuple[str | None, pd.DataFrame]]:
    """The boards every table, ECDF and ranking is computed on: a suite without subsets has
    one, unnamed (its files look as before subsets existed); a suite with subsets has one per
    board of :meth:`~fkopt.kinbench.config.SuiteConfig.board_cells`, each only on the cells
    all its solvers ran (:func:`fkopt.kinbench.measures.boards`). Cut once per result: every
    table and the ECDF figures ask for them."""
    got = sr.__dict__.get("_boards")
    if got is None or got[0] is not sr.record:
        boards = [(None, sr.record)] if not sr.config.subsets else M.boards(sr.record, sr.config.board_cells())
        got = sr.__dict__["_boards"] = (sr.record, boards)
    return got[1]


def split_scope(scope: str) -> tuple[str | None, str]:
    """(board, scope within it) of a leaderboard/ECDF scope ("board:per-point/track:black-box")."""
    if scope.startswith(BOARD_PREFIX) and "/" in scope:
        board, rest = scope[len(BOARD_PREFIX):].split("/", 1)
        return board, rest
    return None, scope


def _per_board(sr, table, column: str) -> pd.DataFrame | None:
    """``table(runs)`` of every board, the board named in ``column`` ("scope": as its prefix;
    "board": a first column) when the suite has boards."""
    frames = []
    for name, runs in suite_boards(sr):
        t = table(runs)
        if t is None or t.empty:
            continue
        if name is not None:
            t = t.copy()
            if column == "scope":
                t["scope"] = f"{BOARD_PREFIX}{name}/" + t["scope"].astype(str)
            else:
                t.insert(0, "board", name)
        frames.append(t)
    return pd.concat(frames, ignore_index=True) if frames else None


def measures_table(sr) -> pd.DataFrame:
    return _per_board(sr, lambda runs: M.measures_table(runs, sr.config.targets), "board")


def ecdf_table(sr) -> pd.DataFrame:
    return _per_board(sr, lambda runs: M.ecdf_table(runs, sr.config.targets, sr.config.budget_per_dim), "scope")


def leaderboard_table(sr) -> pd.DataFrame:
    c = sr.config
    return _per_board(sr, lambda runs: M.leaderboard_table(runs, c.targets, c.budget_per_dim, bootstrap=c.bootstrap,
                                                           alpha=c.alpha, seed=c.seed), "scope")


def ert_ratio_table(sr) -> pd.DataFrame | None:
    """ert_ratio.csv (suites with subsets, kinbench v3's evaluations board): per board, problem,
    track and target, each solver's ERT over the virtual best solver's (COCO's ERT ratio)."""
    if not sr.config.subsets:
        return None
    return _per_board(sr, lambda runs: M.ert_ratio_table(runs, sr.config.targets), "board")


def timing_table(sr) -> pd.DataFrame:
    """Per (problem, solver): the batched solve's wall time over its (pose, run) rows (the one
    timing writer, :func:`fkopt.run.record.timing_table`)."""
    settings = {(p, s): {"runs": int(g["runs"].sum()), "total_s": float(g["seconds"].sum())}
                for (p, s), g in sr.timing.groupby(["problem", "solver"], sort=False)}
    return record.timing_table(sr.timing, settings, by=("problem", "solver"))


def scaling_table(sr) -> pd.DataFrame | None:
    return _per_board(sr, lambda runs: M.scaling_table(runs, sr.config.targets), "board")


def scaling_target(targets) -> float:
    """The target the scaling figure and section show: the middle of the ladder (1e-6 of v1-v3's)."""
    return sorted(targets, reverse=True)[len(targets) // 2]


def answers_table(sr) -> pd.DataFrame | None:
    """answers.csv.gz: every answer of the clock track (joints q0.., wall time, claim, and
    fkopt's verdict), so anyone can re-verify the board."""
    return sr.own.answers


def throughput_table(sr) -> pd.DataFrame | None:
    return sr.own.throughput


def robots_board_table(sr) -> pd.DataFrame | None:
    """leaderboard-robots.csv of a suite's result (:func:`robots_board` of its clock-track answers)."""
    return robots_board(sr.config, sr.own.answers, sr.own.throughput)


def robots_board(config, answers: pd.DataFrame | None, tp: pd.DataFrame | None) -> pd.DataFrame | None:
    """leaderboard-robots.csv: per (solver, robot, timeout) the success share at every rung of
    the ladder within the timeout, the time to an answer at the track's rung (median/p95, ms
    and as a ratio to the reference on the same query), the throughput at the largest batch
    (queries/s and its ratio to the reference's rate; empty for solvers that take no batches)
    and the entry (organiser / outside). Sorted per robot and timeout by success at the rung,
    then by median ratio."""
    if answers is None or answers.empty:
        return None
    clock = config.tracks.clock
    fk = answers.groupby("problem", sort=False)["leg_residual"].apply(lambda v: v.notna().any())
    parts = []
    for is_fk, timeouts, reference in ((False, clock.timeouts_ms, clock.reference),
                                       (True, clock.fk_timeouts_ms, clock.fk_reference)):
        robots = [r for r, f in fk.items() if bool(f) == is_fk]
        if robots:
            parts.append(clock_board(answers[answers["problem"].isin(robots)], timeouts_ms=tuple(timeouts),
                                     reference=reference, rung=clock.rung))
    board = pd.concat(parts, ignore_index=True)
    board["throughput_batch"], board["throughput_qps"], board["throughput_ratio"] = np.nan, np.nan, np.nan
    if tp is not None and not tp.empty:
        top = tp.sort_values("batch").groupby(["solver", "robot"], sort=False).last()
        for (solver, robot), row in top.iterrows():
            at = (board["solver"] == solver) & (board["robot"] == robot)
            board.loc[at, ["throughput_batch", "throughput_qps", "throughput_ratio"]] = \
                [row["batch"], row["queries_per_s"], row["ratio"]]
    key = f"success_{rung_label(LADDER[clock.rung])}"
    board["rung"] = rung_label(LADDER[clock.rung])
    order = {r: k for k, r in enumerate(dict.fromkeys(board["robot"]))}
    board = board.assign(_r=board["robot"].map(order), _s=-board[key])
    board = board.sort_values(["_r", "timeout_ms", "_s", "time_ratio_median"], kind="stable").drop(columns=["_r", "_s"])
    lead = ["solver", "robot", "timeout_ms", "entry"]
    return board[lead + [c for c in board.columns if c not in lead]].reset_index(drop=True)


def spread_labels(ys, gap: float, lo: float = -np.inf, hi: float = np.inf) -> list[float]:
    """Label heights near ``ys`` at least ``gap`` apart (in the order of ``ys``) and inside
    [``lo``, ``hi``], so that the names at the right end of ECDF lines that end together overlap
    neither each other nor, above the axes, the title (too many names for the span: evenly spread
    over it)."""
    ys = np.asarray(ys, dtype=float)
    if len(ys) == 0:
        return []
    order = np.argsort(ys, kind="stable")
    if np.isfinite(hi) and np.isfinite(lo) and len(ys) > 1:
        gap = min(gap, (hi - lo) / (len(ys) - 1))
    out = np.clip(ys, lo, hi)
    for a, b in zip(order[:-1], order[1:]):          # upwards, apart
        out[b] = max(out[b], out[a] + gap)
    if out[order[-1]] > hi:                           # pushed past the top: back down, apart
        out[order[-1]] = hi
        for a, b in zip(order[::-1][:-1], order[::-1][1:]):
            out[b] = min(out[b], out[a] - gap)
    return out.tolist()


def end_labels(ax, ends, gap: float = 0.045, lo: float = 0.0, hi: float = 1.0) -> None:
    """Name each line at its right end (COCO), ``ends`` = [(name, x, y, colour)], the names
    spread apart inside the axes' height (:func:`spread_labels`), clear of title and legend."""
    for (name, x_end, _, color), y in zip(ends, spread_labels([e[2] for e in ends], gap, lo, hi)):
        ax.annotate(name, (x_end, y), xytext=(4, 0), textcoords="offset points", fontsize=7, color=color,
                    va="center", annotation_clip=False)


def wrapped_title(ax, text: str, width: int = 72) -> None:
    """The title in lines of at most ``width`` characters (a long one ran past the figure)."""
    import textwrap
    ax.set_title("\n".join(textwrap.wrap(text, width)), fontsize=8)


def legend_below(ax, fontsize: int = 7) -> None:
    """The legend (the tracks' line styles) under the x-axis label, in columns: the right
    margin is the lines' end labels'."""
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        ax.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=min(3, len(handles)),
                  borderaxespad=0.0, fontsize=fontsize)


def pooled_clock_curves(answers: pd.DataFrame, clock) -> tuple[list, float, int]:
    """Per solver over every IK arm at the largest timeout: the sorted times (ms) of answers
    right at the board's rung within the timeout, and the number of queries it was given;
    the virtual best (per query the fastest right answer of any solver) last."""
    ik = answers
    if "leg_residual" in answers:           # FK of parallel mechanisms: another ladder of timeouts
        fk = answers.groupby("problem", sort=False)["leg_residual"].transform(lambda v: v.notna().any())
        ik = answers[~fk.to_numpy(bool)]
    t = max(clock.timeouts_ms)
    a = ik[(ik["given_timeout_ms"].isna() | (ik["given_timeout_ms"] == t)) & (ik["source"] == "run")]
    ok = rung_success(a)[:, clock.rung] & (a["seconds"].to_numpy() <= t / 1e3)
    a = a.assign(_ms=np.where(ok, 1e3 * a["seconds"].to_numpy(), np.inf))
    curves = []
    for solver, g in a.groupby("solver", sort=False):
        per_query = g.groupby(["problem", "pose"])["_ms"].min()
        curves.append((solver, per_query, g["problem"].nunique()))
    curves.append(("virtual best", a.groupby(["problem", "pose"])["_ms"].min(), a["problem"].nunique()))
    return curves, t, a["problem"].nunique()


def clock_figures(sr, folder: Path, tables: dict) -> list[str]:
    """One ECDF per robot of the clock track at its largest timeout: the share of queries
    answered at the track's rung (kinbench's verdict) against the time to the answer (ms, log),
    one step line per solver and the virtual best solver (per query the fastest right answer of
    any solver run here), the timeout marked; names at the right end, spread apart."""
    answers = tables.get("answers.csv.gz")
    if answers is None or answers.empty:
        return []
    clock = sr.config.tracks.clock
    pyplot = plt()
    names = []
    stems = file_names(answers["problem"].unique(), reserved=("all",))   # distinct robots, and clock_all
    for robot, a in answers.groupby("problem", sort=False):
        fk = a["leg_residual"].notna().any()
        t = max(clock.fk_timeouts_ms if fk else clock.timeouts_ms)
        a = a[(a["given_timeout_ms"].isna() | (a["given_timeout_ms"] == t)) & (a["source"] == "run")]
        n = a["pose"].nunique()
        ok = rung_success(a)[:, clock.rung] & (a["seconds"].to_numpy() <= t / 1e3)
        ms = np.where(ok, 1e3 * a["seconds"].to_numpy(), np.inf)
        a = a.assign(_ms=ms)
        curves = [(solver, g.groupby("pose")["_ms"].min(), n) for solver, g in a.groupby("solver", sort=False)]
        curves.append(("virtual best", a.groupby("pose")["_ms"].min(), n))
        fig = _clock_figure(pyplot, curves, t, f"share of {n} queries",
                            f"{sr.config.name}: {robot}, answers right at {rung_words(rung_label(LADDER[clock.rung]))} "
                            "(kinbench's FK)")
        names += plotting.save(fig, folder / f"clock_{stems[robot]}.png")
        pyplot.close(fig)
    curves, t, arms = pooled_clock_curves(answers, clock)
    if arms:
        curves = [(solver if n_arms == arms else f"{solver} ({n_arms} arms)", per_query, len(per_query))
                  for solver, per_query, n_arms in curves]
        fig = _clock_figure(pyplot, curves, t, "share of the queries it was given",
                            f"{sr.config.name}: IK of all {arms} arms, answers right at "
                            f"{rung_words(rung_label(LADDER[clock.rung]))} (kinbench's FK)")
        names += plotting.save(fig, folder / "clock_all.png")
        pyplot.close(fig)
    return names


def _clock_figure(pyplot, curves, t: float, ylabel: str, title: str):
    """One clock ECDF: per (name, per-query time in ms (inf: no right answer), queries) a step
    line of the share answered against the time (log), named at its right end."""
    fig, ax = pyplot.subplots(figsize=(5.6, 3.6))
    ends = []
    for solver, per_query, n in curves:
        x = np.sort(per_query.to_numpy())
        x = x[np.isfinite(x)]
        y = np.arange(1, len(x) + 1) / n
        xs, ys = np.concatenate([[1e-3], x, [t]]), np.concatenate([[0.0], y, [y[-1] if len(y) else 0.0]])
        style = {"color": "black", "linestyle": ":"} if solver.startswith("virtual best") else {}
        line, = ax.step(xs, ys, where="post", **style)
        ends.append((solver, t, ys[-1], line.get_color()))
    end_labels(ax, ends)
    ax.axvline(t, color="grey", linewidth=0.8)
    ax.set_xscale("log")
    ax.set_xlim(1e-2, t * 1.05)
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel(f"time to an answer (ms); timeout {t:g} ms marked")
    ax.set_ylabel(ylabel)
    wrapped_title(ax, title)
    return fig


def board_top_lines(folder: Path, top: int = 3) -> list[str]:
    """What ``fkopt suite`` prints when it ends: the first ``top`` rows of each track's overall
    ranking (leaderboard.csv) and the top of the per-robot board (leaderboard-robots.csv)."""
    folder = Path(folder)
    lines = []
    lb_path = folder / "leaderboard.csv"
    if lb_path.exists():
        lb = read_stored_csv(folder, "leaderboard.csv")
        for scope, g in lb.groupby("scope", sort=False):
            if split_scope(scope)[1].startswith("track:"):
                best = ", ".join(f"{r.solver} {r.score:.3f}" for r in g.head(top).itertuples())
                lines.append(f"{scope} (score, evaluations): {best}")
    robots = folder / "leaderboard-robots.csv"
    if robots.exists():
        lines += robots_top_lines(read_stored_csv(folder, robots.name), top)
    return lines


def robots_top_lines(board: pd.DataFrame, top: int = 3) -> list[str]:
    """The top of the per-robot board in physical units: per robot, at the largest timeout,
    the first ``top`` solvers with success at every rung (%) and the median time (ms, and as a
    ratio to the reference)."""
    success = [c for c in board.columns if c.startswith("success_")]
    lines = []
    for robot, g in board.groupby("robot", sort=False):
        t = g["timeout_ms"].max()
        g = g[g["timeout_ms"] == t]
        ref = g["reference"].iloc[0]
        lines.append(f"{robot} (timeout {t:g} ms; time to an answer at {g['rung'].iloc[0]}, ratio to {ref}; "
                     f"success at {', '.join(c[len('success_'):] for c in success)}):")
        for _, row in g.head(top).iterrows():
            pct = " / ".join(f"{100 * row[c]:.0f}" for c in success)
            qps = "" if np.isnan(row["throughput_qps"]) else f", {row['throughput_qps']:.0f} queries/s at batch {row['throughput_batch']:.0f}"
            other = "" if "other_mode" not in row or pd.isna(row["other_mode"]) else \
                f", another assembly mode {100 * row['other_mode']:.0f} %"
            lines.append(f"  {row['solver']:<16} [{row['entry']}] success {pct} %{other}, median {row['time_ms_median']:.3g} ms "
                         f"(x{row['time_ratio_median']:.3g}), p95 {row['time_ms_p95']:.3g} ms (x{row['time_ratio_p95']:.3g}){qps}")
    return lines


def ecdf_figures(sr, folder: Path, tables: dict) -> list[str]:
    """One ECDF figure per scope (all problems, each class): the share of (problem, pose,
    target, run) reached against log10(evaluations / dimension), one step line per solver,
    named at its right end as COCO does; tracks told apart by line style."""
    df = tables.get("ecdf.csv")
    if df is None or df.empty:
        return []
    pyplot = plt()
    styles = {"black-box": "-", "jacobian": "--", "exact": ":"}
    names = []
    targets = ", ".join(f"{t:.0e}" for t in sr.config.targets)
    # one file per scope: a class "all" does not overwrite ecdf_all, "a b" and "a_b" differ;
    # a board's scopes are ecdf_<board>_all, ecdf_<board>_<class>
    def short(scope):
        board, rest = split_scope(scope)
        rest = rest.removeprefix("class:")
        return rest if board is None else f"{board}_{rest}"
    scopes = [s for s in df["scope"].unique() if s != "all"]
    stems = file_names((short(s) for s in scopes), reserved=("all",))
    rows_of = {}                                   # scope -> its run rows (the virtual best's cells)
    for board, runs in suite_boards(sr):
        prefix = "" if board is None else f"{BOARD_PREFIX}{board}/"
        rows_of[f"{prefix}all"] = runs
        rows_of.update({f"{prefix}class:{c}": r for c, r in runs.groupby("class", sort=True)})
    for scope, g in df.groupby("scope", sort=False):
        fig, ax = pyplot.subplots(figsize=(5.2, 3.6))
        top = float(sr.config.budget_per_dim)
        curves = list(g.groupby(["solver", "track"], sort=False))
        if scope in rows_of and g["solver"].nunique() > 1:
            curves.append((("virtual best", "best"), M.virtual_best_ecdf(rows_of[scope], sr.config.targets)))
        ends = []
        for (solver, track), s in curves:
            s = s.dropna(subset=["evals_per_dim"])      # a solver that reached nothing: flat at 0
            b = np.concatenate([[1.0], np.maximum(s["evals_per_dim"].to_numpy(), 1.0), [top]])
            f = np.concatenate([[0.0], s["fraction"].to_numpy(), [s["fraction"].max() if len(s) else 0.0]])
            x, y = np.log10(b), f
            style = {"color": "black", "linestyle": ":", "linewidth": 1.6} if track == "best" else \
                {"linestyle": styles.get(track, "-")}
            line, = ax.step(x, y, where="post", label=f"{solver} ({track})" if track != "best" else solver, **style)
            ends.append((solver, x[-1], y[-1], line.get_color()))
        end_labels(ax, ends)          # names at the right end (COCO), apart, inside the axes' height
        ax.axvline(np.log10(top), color="grey", linewidth=0.8)     # the budget
        ax.set_xlabel(f"log10(evaluations / dimension); budget {top:g} x dimension marked")
        ax.set_ylabel("fraction of (problem, pose, target, run)")
        ax.set_ylim(-0.02, 1.02)
        board, within = split_scope(scope)
        what = "all problems" if within == "all" else within.split(":", 1)[1]
        if board is not None:
            what = f"board {board} (the cells all its solvers ran), {what}"
        wrapped_title(ax, f"{sr.config.name}: {what}; targets {targets}")
        legend_below(ax)
        stem = "ecdf_all" if scope == "all" else f"ecdf_{stems[short(scope)]}"
        names += plotting.save(fig, folder / f"{stem}.png")
        pyplot.close(fig)
    return names


def scaling_figures(sr, folder: Path, tables: dict) -> list[str]:
    """One figure per class of several dimensions (scaling.csv): log10(ERT / dimension) at the
    middle target against the dimension, one line per solver; a dimension no run of a solver
    solved is left out of its line (ERT infinite), as COCO's scaling plots do."""
    df = tables.get("scaling.csv")
    if df is None or df.empty:
        return []
    pyplot = plt()
    styles = {"black-box": "-", "jacobian": "--", "exact": ":"}
    target = scaling_target(sr.config.targets)
    names = []
    shown = df[np.isclose(df["target"], target)]
    if "board" in shown.columns:                      # one figure per (board, class)
        shown = shown.assign(**{"class": shown["board"] + "_" + shown["class"]})
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
        names += plotting.save(fig, folder / f"scaling_{stems[cls]}.png")
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


ROBOTS_PREAMBLE = ("IK of real arms, every answer checked by fkopt's FK (position m, geodesic rotation rad, "
                   "joint limits), whatever the solver claims; success within the timeout at each rung; time to "
                   "an answer (a failure counted at the timeout) in ms and as a ratio to the reference solver "
                   "measured in the same job on the same query; entry: organiser (fkopt's own) or outside "
                   "(docs/kinbench.md, v3).")


def robot_columns(board: pd.DataFrame) -> list[str]:
    return (["solver", "robot", "timeout_ms", "entry"] + [c for c in board.columns if c.startswith("success_")]
            + ["time_ms_median"] + (["cpu_ms_median"] if "cpu_ms_median" in board else [])
            + ["time_ratio_median", "time_ratio_p95", "throughput_qps"]
            + (["not_applicable"] if "not_applicable" in board else []))


PER_PROBLEM = ["set", "solver", "track", "target", "trials", "success_rate", "ert"]


def boards_preamble(c) -> str:
    """What the boards of a suite with subsets are (leaderboard.md and index.html)."""
    if not c.subsets:
        return ""
    parts = []
    for name, defining in c.board_cells():
        sub = next((s for s in c.subsets if s.name == name), None)
        if sub is None:
            parts.append(f"board '{name}': every problem, set and pose, {c.runs} runs, defined by "
                         f"{', '.join(defining)}")
            continue
        probs = f"{len(sub.problems)} problems" if sub.problems else "every problem"
        sets = ", ".join(sub.sets) if sub.sets else "every set"
        poses = f"the first {sub.poses} poses" if sub.poses else "every pose"
        parts.append(f"board '{name}': {probs}, {sets}, {poses} of each set, {sub.runs or c.runs} runs, defined by "
                     f"{', '.join(defining)}")
    return ("Boards: each compares only the solvers that ran every cell (problem, set, pose, run) of it, "
            "on those cells; a solver with fewer cells is not on a board, and a solver with more is "
            "judged on the board's cells only. " + "; ".join(parts) + ".")


def ert_ratio_sections(tables: dict) -> list[tuple[str, pd.DataFrame]]:
    """(board / class / track, solvers x targets: median ERT ratio to the virtual best solver)."""
    er = tables.get("ert_ratio.csv")
    if er is None or er.empty:
        return []
    out = []
    for (board, cls, track), g in er.groupby(["board", "class", "track"], sort=False):
        summary = M.ert_ratio_summary(g)
        if summary.empty or g["solver"].nunique() < 2:     # a track of one solver is its own best
            continue
        wide = summary.pivot_table(index="solver", columns="target", values="median_ert_ratio", sort=False)
        wide = wide[sorted(wide.columns, reverse=True)]
        wide.columns = [f"ert_ratio_{t:.0e}" for t in wide.columns]
        out.append((f"board:{board}/class:{cls}/track:{track}", wide.reset_index()))
    return out


ERT_RATIO_NOTE = ("ERT ratio to the virtual best solver (COCO): per problem and target, a solver's ERT over the "
                  "smallest ERT of any solver of its track on the board; the median over the class's problems "
                  "(only problems some solver of the track solved at that target); 1 = the best, inf = never "
                  "reached where another did. ert_ratio.csv has every problem.")


def leaderboard_markdown(sr, folder: Path, tables: dict) -> list[str]:
    lb = tables.get("leaderboard.csv")
    if lb is None:
        return []
    c = sr.config
    cols = leaderboard_columns(lb)
    out = [f"# {md_text(c.title or c.name)}", "", md_text(preamble(c)), ""]
    robots = tables.get("leaderboard-robots.csv")
    if robots is not None:
        out += ["## Per robot, on the clock", "", ROBOTS_PREAMBLE, "", _md_table(robots, robot_columns(robots)), ""]
    if c.subsets:
        out += [md_text(boards_preamble(c)), ""]
    for title, pred in (("Overall", lambda s: s == "overall"), ("Per track", lambda s: s.startswith("track:")),
                        ("Per problem class", lambda s: s.startswith("class:"))):
        out += [f"## {title}", ""]
        for scope, g in leaderboard_sections(tables):
            if pred(split_scope(scope)[1]):
                out += [f"### {md_text(scope)}", "", _md_table(g, cols), ""]
    ratios = ert_ratio_sections(tables)
    if ratios:
        out += ["## ERT ratio to the virtual best solver", "", ERT_RATIO_NOTE, ""]
        for scope, g in ratios:
            out += [f"### {md_text(scope)}", "", _md_table(g, list(g.columns)), ""]
    sc = tables.get("scaling.csv")
    if sc is not None:
        target = scaling_target(c.targets)
        out += ["## Cost against dimension", "", f"ERT (evaluations) and ERT / dimension at target {target:.0e} "
                "over every problem, set and pose of a dimension, for the classes of several dimensions "
                "(scaling.csv has every target).", ""]
        by = ["board", "class"] if "board" in sc.columns else "class"
        for cls, g in sc[np.isclose(sc["target"], target)].groupby(by, sort=True):
            name = "/".join(cls) if isinstance(cls, tuple) else cls
            out += [f"### {md_text(name)}", "", _md_table(g.sort_values(["solver", "dim"], kind="stable"), SCALING), ""]
    ms = tables.get("measures.csv")
    if ms is not None:
        out += ["## Per problem", "", "Success rate and ERT (evaluations) per set and target.", ""]
        per_problem = (["board"] if "board" in ms.columns else []) + PER_PROBLEM
        for problem, g in ms.groupby("problem", sort=False):
            out += [f"### {md_text(problem)}", "", _md_table(g, per_problem), ""]
    tim = tables.get("timing.csv")
    if tim is not None and not tim.empty:
        out += ["## Wall time per solve", "", "Amortised: the batched solve's wall time over its "
                "(pose, run) rows, in this process's worker; not compared by fkopt check.", "",
                _md_table(tim, ["problem", "solver", "runs", "amortised_ms_per_run"]), ""]
    (folder / "leaderboard.md").write_text("\n".join(out), encoding="utf-8")
    return ["leaderboard.md"]


def meta(sr) -> dict:
    c = sr.config
    manifest = sr.own.manifest or {}
    canonical = hashlib.sha256(json.dumps(manifest, sort_keys=True).encode()).hexdigest()
    return {"kind": "suite", "name": c.name, "paper": c.paper, "config": c.stored_dump(),
            "config_file": sr.source,
            "pose_sets": {"version": manifest.get("version"), "manifest_canonical_sha256": canonical},
            "outside": {o.solver: digest(c, o, sr.own.files) for o in c.outside},
            "measures": "fkopt.kinbench.measures (COCO: success rate, ERT, ECDF; bootstrap ranking, Holm)",
            **board_meta(sr), **submissions_meta(c, sr.own.files)}


def board_meta(sr) -> dict:
    """meta.json's record of a per-robot board (only for a suite with a clock track): its frozen
    board version (:data:`fkopt.kinbench.releases.BOARDS`), the machine's load averages at the
    clock track's start and end, and every entry's settings."""
    if sr.own.answers is None:
        return {}
    out = {"board_version": board_version(sr.config.name)}
    if sr.own.load_avg:
        out["load_avg"] = sr.own.load_avg
    if sr.own.entries:
        out["entries"] = sr.own.entries
    return {k: v for k, v in out.items() if v is not None}


def submissions_meta(c, files=None) -> dict:
    """meta.json's record of the clock track's outside submissions (only when there are any)."""
    subs = c.tracks.clock.submissions if c.tracks is not None and c.tracks.clock is not None else []
    if not subs:
        return {}
    return {"submissions": {s.solver: {"sha256": submission_digest(c, s, files), "machine": s.machine, "file": s.file,
                                       "description": s.description} for s in subs}}


def report_section(exp, root: Path) -> str:
    """A stored suite's section of REPORT.md (:attr:`fkopt.run.tasks.Kind.report_section`; ``exp``: a
    :class:`fkopt.reproduce.store.Experiment`): its overall leaderboard, linked to its page and tables."""
    rel = exp.folder.relative_to(root)
    lines = [f"### {exp.title}", "",
             f"Results: [`results/{rel}/`]({rel}/) · page: [`index.html`]({rel}/index.html) · "
             f"leaderboards: [`leaderboard.md`]({rel}/leaderboard.md) · seed {exp.config.get('seed')}, "
             f"{exp.config.get('runs')} runs per pose, {exp.config.get('budget_per_dim')} x dimension "
             "evaluations ([docs/kinbench.md](../docs/kinbench.md)).", ""]
    if exp.has("leaderboard.csv"):
        board = exp.table("leaderboard")
        # a suite with subsets has one overall ranking per board ("board:<name>/overall")
        overall = board[board["scope"].astype(str).str.split("/").str[-1] == "overall"] if "scope" in board.columns else board
        cols = [c for c in ("rank", "solver", "track", "score", "ci_low", "ci_high", "better_than") if c in board.columns]
        if "scope" in overall.columns and overall["scope"].nunique() > 1:
            cols = ["scope", *cols]
        lines += ["Overall (tracks mixed, for reference; each track is ranked on its own in the leaderboard):", "",
                  md_table(overall[cols].astype(object).fillna("")), ""]
    return "\n".join(lines)
