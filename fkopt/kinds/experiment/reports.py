"""Reports: turn an experiment's :class:`~fkopt.run.result.RunResult` into CSV tables, figures and
``meta.json`` (its run record, timing record and trace; its cases and per-iteration curves in
``own``: :class:`~fkopt.kinds.experiment.runner.ExperimentOwn`).

The makers below are listed, with each file's role (table, curves, timing, figure), in
:data:`fkopt.run.writers.OUTPUTS`, and :func:`fkopt.run.writers.write_outputs` writes them. Files of one
experiment folder (all deterministic for a given seed except ``timing.csv``, ``timing_runs.csv`` and
the figures drawn from timings, ``cases_time.png``):

* ``summary.csv``     final fitness statistics per case and algorithm over all runs (mean, std,
  best, worst, median), evaluations, success rate and iterations/evaluations to the threshold
  (medians over the runs that reached it), the paper's printed values beside them;
* ``timing.csv``      time per run (ms) measured one run at a time on a sample of runs (median,
  quartiles; see :mod:`.timing`), the batch's amortised time beside it, the printed time;
  ``timing_runs.csv`` every timed run;
* ``values.csv``      per variable: target, the median run's value and error (the run whose final
  fitness is the lower median), the best run's, and the mean absolute error over all runs;
* ``inputs.csv``      (only when a case gives both joints and a pose) given vs computed inputs;
* ``solutions.csv``   (only with an exact solver's ``solutions: all`` entry) one row per (case, entry,
  solution): every solution of the case's pose in the mechanism's public units (an arm's joints,
  a parallel mechanism's pose), its errors (position and geodesic rotation; residual and hits),
  the case's seed and how the search decided it had them all (its stopping rule's settings and
  counts); a case without a solution keeps one row, solution 0 with empty values. Such an entry
  has no runs: the files above hold the other entries (none of them when there are none);
* ``runs.csv``        one row per run (incl. ``iterations_to_best``: first iteration at which the
  run's final best-so-far fitness was reached);
* ``trace.csv.gz``    per-run best-so-far fitness where it changed, with evaluations (equal-evaluation
  comparisons of the claims);
* ``convergence.csv`` best-so-far fitness per iteration: median and quartiles over runs, mean
  evaluations; ``convergence.png`` the same on a log scale (vs iterations and vs evaluations);
* optional figures (``figures:`` in the config): ``variables.png``, ``snapshot_<t>.png``,
  ``extras.png``, ``cases.png`` + ``cases_time.png`` (+ ``cases_position_error.png`` for
  serial arms), ``time.png``, ``position_error.png``; each figure is named after the paper
  figure it mirrors when the config's ``figure_names`` says so (``{convergence: fig2}`` ->
  ``fig2.png``) and has a PDF twin (:mod:`.plotting`);
* ``meta.json``       what the config and the seed fix: config, seeds (per case and algorithm),
  mechanism, objective, and the SHA-256 of every deterministic CSV (``files``);
* ``env.json``        where it ran: fkopt and library versions, platform, the platform fingerprint
  (:mod:`fkopt.run.provenance`); like ``timing.csv`` it changes with the machine.

A folder is written into a temporary sibling first and swapped into place
(:func:`fkopt.files.write_atomically`), so a failed or interrupted run never leaves a
half-written results folder and never loses the previous one.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.registry import algorithm_class
from fkopt.run import record
from fkopt.run.result import RunResult
from fkopt.run.writers import FLOAT, write_outputs, write_result
from fkopt.run import plotting
from fkopt.kinds.experiment.runner import one_answer_entries, outputs_of, pose_error
from fkopt.run.solving import budget

#: Fitness of exactly 0 cannot be drawn on a log axis; it is drawn at this floor (and said so).
LOG_FLOOR = 1e-32
#: Beyond this many cases, convergence curves are pooled over all (case, run) pairs.
MAX_CASE_CURVES = 6

# -- tables ------------------------------------------------------------------------------------
def summary_table(er: RunResult) -> pd.DataFrame:
    """Per case and algorithm, over its runs: the run record's (the one summary writer,
    :func:`fkopt.run.record.summary_table`), with each algorithm's settings from the config; None
    without runs (only ``solutions: all`` entries)."""
    if er.record is None:
        return None
    settings = {}
    for spec in one_answer_entries(er.config):
        b = budget(er.config, spec)
        # sorted: a config reloaded from meta.json has sorted keys
        printed = {f"printed_{k}": v for k, v in sorted(spec.printed.items()) if not k.endswith("_ms")}
        settings[spec.key] = {"method": spec.name, "population": b["population"], "iterations": b["iterations"],
                              "runs": b["runs"], "printed": printed}
    return record.summary_table(er.record, settings, er.config.threshold)


def timing_table(er: RunResult) -> pd.DataFrame:
    """Time per run measured one run at a time on a sample of runs (:mod:`.timing`), per timed
    case and algorithm (the one timing writer, :func:`fkopt.run.record.timing_table`); then each
    ``solutions: all`` entry's search of every case (its one batch: ``runs`` 1)."""
    answering = one_answer_entries(er.config)
    searching = [spec for spec in er.config.algorithms if spec not in answering]
    settings = {(case.label, spec.key): {
        "runs": er.config.runs if spec in answering else 1, "total_s": er.own.solve_s[spec.key],
        **{f"printed_{k}": v for k, v in sorted(spec.printed.items()) if k.endswith("_ms")}}
        for case in er.own.cases for spec in er.config.algorithms}
    names = record.ALGORITHM_NAMES
    keys = {spec.key for spec in searching}
    runs, sets = er.timing[~er.timing["solver"].isin(keys)], er.timing[er.timing["solver"].isin(keys)]
    tables = [record.timing_table(runs, settings, names=names, timed_alone=True)] if len(runs) else []
    tables += [record.timing_table(sets, settings, names=names)] if len(sets) else []
    return pd.concat(tables, ignore_index=True)


def values_table(er: RunResult) -> pd.DataFrame | None:
    if not er.own.solves:
        return None
    mech = er.own.mechanism
    rows = []
    for rec in er.own.solves:
        r, case = rec.result, rec.case
        outputs = outputs_of(mech, r.x)
        med, best = r.median_run, r.best_run
        target = case.target if case.target is not None else case.reference
        printed = case.printed.get(rec.spec.key, {})
        for j, (name, unit) in enumerate(zip(er.own.compared_names, er.own.compared_units)):
            row = {"case": case.label, "algorithm": rec.spec.key, "variable": name, "unit": unit,
                   "target": float(target[j]) if target is not None else np.nan,
                   "median_run": int(r.run_ids[med]), "median_run_value": float(outputs[med, j]),
                   "best_run_value": float(outputs[best, j])}
            if target is not None:
                err = pose_error(mech, outputs, target)[:, j]
                row["median_run_abs_error"] = float(err[med])
                row["best_run_abs_error"] = float(err[best])
                row["mean_abs_error"] = float(np.mean(err))
            if case.reference is not None:
                row[case.reference_label] = float(case.reference[j])
                row[f"median_run_error_vs_{case.reference_label}"] = float(
                    pose_error(mech, outputs[med], case.reference)[j])
            if name in printed:
                row["printed_value"] = printed[name]
                if f"{name}_error" in printed:   # the paper's error column, transcribed, never recomputed
                    row["printed_abs_error"] = printed[f"{name}_error"]
                if target is not None:   # |printed value - target| from the rounded printed value
                    row["printed_value_minus_target"] = _abs_diff(unit, printed[name], float(target[j]))
            rows.append(row)
    return pd.DataFrame(rows)


def _abs_diff(unit: str, a: float, b: float) -> float:
    d = a - b
    return float(abs((d + 180.0) % 360.0 - 180.0) if unit == "deg" else abs(d))


def inputs_table(er: RunResult) -> pd.DataFrame | None:
    mech = er.own.mechanism
    rows = []
    for case in er.own.cases:
        if case.given_joints is None or case.joints_from_pose is None:
            continue
        for name, unit, g, c in zip(mech.joint_names, mech.joint_units, case.given_joints, case.joints_from_pose):
            rows.append({"case": case.label, "joint": name, "unit": unit, "given": float(g),
                         "from_nominal_pose": float(c), "difference": float(g - c)})
    return pd.DataFrame(rows) if rows else None


def solutions_table(er: RunResult) -> pd.DataFrame | None:
    """``solutions.csv``: every ``solutions: all`` entry's solutions, case by case (module
    docstring); None without such an entry."""
    if not er.own.sets:
        return None
    frames = []
    for s in er.own.sets:
        found, k = s.found, len(s.found.values)
        rows = max(k, 1)                                 # a case without a solution keeps its search's row
        values = found.values if k else np.full((1, len(found.names)), np.nan)
        cols = {"case": s.case.label, "algorithm": s.spec.key, "solution": np.arange(1, k + 1) if k else [0]}
        cols.update({name: values[:, j] for j, name in enumerate(found.names)})
        cols.update({name: v if k else [np.nan] for name, v in found.per_solution.items()})
        cols.update({"seed": s.seed, **found.search})
        frames.append(pd.DataFrame(cols, index=range(rows)))
    return pd.concat(frames, ignore_index=True)


def convergence_table(er: RunResult) -> pd.DataFrame | None:
    """``convergence.csv``: per (case, algorithm) and iteration, the median, quartiles, min and max
    over the runs of the best-so-far fitness the algorithm *keeps* (each solve's ``history``: the
    papers' curve), the mean evaluations, and a serial arm's median position error.

    Not computed from ``trace.csv.gz``, on purpose: the trace is the evaluation log (IOHprofiler's
    best *evaluated* fitness at logged evaluation counts) and the two differ where an algorithm
    discards a better evaluated point -- ABC with ``selection: karaboga`` compares 1/(1+f), which is
    1.0 for every f below ~1.1e-16, so it keeps an older source (``mao2017/tab3_floor``: kept
    4e-18..1.1e-16, evaluated 1e-19..1.6e-17 in its 90 runs; the paper's printed floor is the kept one).
    docs/design.md, "The trace and the curves are two records"."""
    if not er.own.solves:
        return None
    frames = []
    for label, algo, hist, evals, pos in _curves(er):
        q25, med, q75 = np.percentile(hist, [25, 50, 75], axis=0)
        df = pd.DataFrame({"case": label, "algorithm": algo, "iteration": np.arange(hist.shape[1]),
                           "median": med, "q25": q25, "q75": q75, "min": hist.min(axis=0),
                           "max": hist.max(axis=0), "mean_evaluations": evals.mean(axis=0)})
        if pos is not None:
            df["median_position_error"] = np.median(pos, axis=0)
        frames.append(df)
    return pd.concat(frames, ignore_index=True)


def _curves(er: RunResult):
    """(case label, algorithm, history, evaluation history, position error history) per curve."""
    pooled = len(er.own.cases) > MAX_CASE_CURVES
    if not pooled:
        for rec in er.own.solves:
            yield (rec.case.label, rec.spec.key, rec.result.history, rec.result.evaluation_history,
                   rec.position_error_history)
        return
    for spec in one_answer_entries(er.config):
        recs = [r for r in er.own.solves if r.spec.key == spec.key]
        pos = [r.position_error_history for r in recs]
        yield ("all", spec.key, np.concatenate([r.result.history for r in recs]),
               np.concatenate([r.result.evaluation_history for r in recs]),
               np.concatenate(pos) if pos[0] is not None else None)


# -- figures -------------------------------------------------------------------------------------
# Style, names, units and the honest drawing of zeros: :mod:`.plotting`.
def _plt():
    return plotting.plt()


def _save(fig, path: Path) -> list[str]:
    return plotting.save(fig, path)


def figure_file(er: RunResult, kind: str) -> str:
    """The PNG name of a figure kind: the paper figure it mirrors (config ``figure_names``) or the kind."""
    return er.config.figure_names.get(kind, kind) + ".png"


def _spec_names(er: RunResult) -> dict[str, str]:
    """Legend names; algorithms that share a paper name (wu2015's five Newton starts) add their label."""
    names = {spec.key: plotting.spec_name(spec) for spec in er.config.algorithms}
    counts = pd.Series(list(names.values())).value_counts()
    return {spec.key: f"{names[spec.key]} · {spec.label}" if counts[names[spec.key]] > 1 and spec.label
            else names[spec.key] for spec in er.config.algorithms}


def _curve_sets(er: RunResult):
    """(name, spec, history, evaluations, position errors, iterations done) per drawn curve; with
    more than MAX_CASE_CURVES cases the runs of all cases are pooled per algorithm."""
    names = _spec_names(er)
    pooled = len(er.own.cases) > MAX_CASE_CURVES
    for spec in one_answer_entries(er.config):
        recs = [r for r in er.own.solves if r.spec.key == spec.key]
        groups = [recs] if pooled else [[r] for r in recs]
        for grp in groups:
            name = names[spec.key] if pooled or len(er.own.cases) == 1 else f"{names[spec.key]} · {grp[0].case.label}"
            pos = [r.position_error_history for r in grp]
            yield (name, spec, np.concatenate([r.result.history for r in grp]),
                   np.concatenate([r.result.evaluation_history for r in grp]),
                   np.concatenate(pos) if pos[0] is not None else None,
                   np.concatenate([r.result.iterations_done for r in grp]))


def _band(ax, xs, values, floor, name, color=None, end=None):
    """Median (and quartile band over several runs) of ``values`` (runs, iterations) up to ``end``."""
    v = np.maximum(values, floor)
    stop = v.shape[1] if end is None else int(end) + 1
    xs = xs[:stop]
    if v.shape[0] == 1:
        line, = ax.plot(xs, v[0, :stop], label=name, color=color)
    else:
        q25, med, q75 = np.percentile(v[:, :stop], [25, 50, 75], axis=0)
        line, = ax.plot(xs, med, label=name, color=color)
        ax.fill_between(xs, q25, q75, color=line.get_color(), alpha=0.18, lw=0)
    if end is not None and stop < values.shape[1]:
        y = v[0, stop - 1] if v.shape[0] == 1 else np.median(v[:, stop - 1])
        ax.plot(xs[-1], y, marker="|", ms=9, mew=1.5, color=line.get_color())
    return line


def convergence_figure(er: RunResult, folder: Path, tables: dict) -> list[str]:
    """Best-so-far fitness vs iteration and vs function evaluations (median and quartiles of the
    runs, or the run itself). Runs that stop at the threshold end where (the median run) stopped
    (a bar); P-ABC's switch from PSO to ABC is marked with a triangle."""
    if not er.own.solves:
        return []
    path = folder / figure_file(er, "convergence")
    plt = _plt()
    curves = list(_curve_sets(er))
    floor = plotting.floor_of(*[c[2] for c in curves])
    zero = any(bool((c[2] <= 0).any()) for c in curves)
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6), sharey=True)
    single = all(c[2].shape[0] == 1 for c in curves)
    for name, spec, hist, evals, _, done in curves:
        end = float(np.median(done)) if er.config.stop_at_threshold else None
        end = None if end is not None and end >= hist.shape[1] - 1 else end
        it = np.arange(hist.shape[1])
        line = _band(axes[0], it, hist, floor, name, end=end)
        _band(axes[1], evals.mean(axis=0), hist, floor, name, color=line.get_color(), end=end)
        phases = getattr(algorithm_class(spec.name), "phase_change", None)   # P-ABC: PSO then ABC
        if phases:
            sw = algorithm_class(spec.name).phase_iteration(spec.params, hist.shape[1] - 1)
            y = np.median(np.maximum(hist[:, sw], floor))
            for ax, x in zip(axes, (sw, evals.mean(axis=0)[sw])):
                ax.plot(x, y, marker="v", ms=7, color=line.get_color(), zorder=5)
            axes[0].annotate(phases, (sw, y), textcoords="offset points", xytext=(4, 8), fontsize=7,
                             color=line.get_color())
    runs = curves[0][2].shape[0]
    what = "best-so-far " + plotting.fitness_label(er.own.mechanism, getattr(er.own.solves[0].problem, "objective", None))
    axes[0].set_ylabel(what)
    threshold = er.config.threshold
    for ax, xl in zip(axes, ("iteration", "function evaluations (mean over runs)")):
        ax.set_yscale("log")
        ax.set_xlabel(xl)
        if zero:
            plotting.mark_zero(ax, floor)
        if threshold is not None:     # what success rates and iterations to the threshold count
            ax.axhline(threshold, color="0.35", lw=0.9, ls=":", zorder=1,
                       label=f"threshold {threshold:g}" if ax is axes[0] else None)
    from matplotlib.ticker import MaxNLocator
    axes[0].xaxis.set_major_locator(MaxNLocator(integer=True))   # iterations are whole numbers
    plotting.legend_off_data(axes[-1], source=axes[0])
    note = "one run" if single else f"median of {runs} runs, band: quartiles"
    if er.config.stop_at_threshold:
        note += f"; runs stop at f < {er.config.threshold:g} (bar: median stop)"
    fig.suptitle(f"{er.config.title or er.config.name}\n({note})", fontsize=9)
    fig.tight_layout()
    names = _save(fig, path)
    plt.close(fig)
    return names


def variables_figure(er: RunResult, folder: Path, tables: dict) -> list[str]:
    """Best-so-far value of each unknown vs iteration for the median run (liu2008 Fig. 4a, wang7dof
    Fig. 4), with the true value dashed (for a redundant arm: the joints that defined the target,
    one of many solutions)."""
    if not er.own.solves:
        return []
    if "variables" not in er.config.figures:
        return []
    path = folder / figure_file(er, "variables")
    plt = _plt()
    recs = [r for r in er.own.solves if r.case.index == 0]
    names = recs[0].result.variable_names
    units = er.own.mechanism.unknown_units
    spec_names = _spec_names(er)
    cols = min(len(names), 4)
    rows = int(np.ceil(len(names) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(2.4 * cols, 2.2 * rows), squeeze=False)
    flat = axes.ravel()
    for rec in recs:
        r = rec.result
        xh = r.x_history[r.median_run]
        end = int(r.iterations_done[r.median_run]) + 1
        for j, ax in enumerate(flat[:len(names)]):
            ax.plot(np.arange(end), xh[:end, j], label=spec_names[rec.spec.key], lw=1.1)
    case = recs[0].case
    if er.own.mechanism.kind == "parallel":
        truth, what = ((case.target, "true value") if case.target is not None
                       else (case.reference, case.reference_label.replace("_", " ")))
    else:
        truth, what = case.given_joints, "joints defining the target"
    for j, ax in enumerate(flat[:len(names)]):
        ax.set_title(f"{names[j]} ({units[j]})")
        # most of the movement is in the first few per cent of the iterations: a logarithmic
        # axis (linear below 1, so iteration 0 is shown) spreads it out
        ax.set_xscale("symlog", linthresh=1, linscale=0.3)
        ax.set_xlabel("iteration (log scale)")
        if truth is not None:
            ax.axhline(truth[j], color="k", lw=0.8, ls="--", label=what, zorder=1)
    for ax in flat[len(names):]:
        ax.set_visible(False)
    # one legend for all panels, below them: never on a curve or on the truth line
    handles, labels = flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 4), fontsize=7)
    runs = recs[0].result.runs
    fig.suptitle(f"{er.config.title or er.config.name}\nbest-so-far variables of the median run "
                 f"(of {runs}), case {case.label}" if runs > 1 else
                 f"{er.config.title or er.config.name}\nbest-so-far variables, case {case.label}", fontsize=9)
    legend_rows = int(np.ceil(len(labels) / 4))
    fig.tight_layout(rect=(0, 0.08 * legend_rows / rows + 0.01, 1, 1))
    out = _save(fig, path)
    plt.close(fig)
    return out


def _shading(problem, bounds, i, j, k, n=121, m=41):
    """log10 of min over variable k of f on an n x n grid of variables (i, j)."""
    gi = np.linspace(*bounds[i], n)
    gj = np.linspace(*bounds[j], n)
    gk = np.linspace(*bounds[k], m)
    X = np.empty((n, n, m, 3))
    X[..., i] = gi[None, :, None]
    X[..., j] = gj[:, None, None]
    X[..., k] = gk[None, None, :]
    f = problem.fitness(X.reshape(-1, 3)).reshape(n, n, m).min(axis=2)
    return gi, gj, np.log10(np.maximum(f, 1e-12))


def snapshot_figures(er: RunResult, folder: Path, tables: dict) -> list[str]:
    """Population at the snapshot iterations, first case, run 0 (wu2015 Figs. 4-6): two projections
    shaded by log10 of the fitness (minimised over the third variable), the true pose and, where the
    mechanism has several exact forward solutions, the mirror solution(s)."""
    if not er.own.solves:
        return []
    if "snapshots" not in er.config.figures:
        return []
    plt = _plt()
    written = []
    recs = [r for r in er.own.solves if r.case.index == 0]
    names_of = _spec_names(er)
    for t in er.config.snapshots:
        panels = []
        for rec in recs:
            if t in rec.result.snapshots and rec.result.snapshots[t].shape[-1] == 3:
                panels.append(rec)
        if not panels:
            continue
        fig, axes = plt.subplots(len(panels), 2, figsize=(8.4, 3.6 * len(panels)), squeeze=False)
        for row, rec in zip(axes, panels):
            pts = rec.result.snapshots[t][0]
            names = rec.result.variable_names
            units = er.own.mechanism.unknown_units
            b = np.asarray(rec.problem.bounds, float)
            truth = rec.case.target if er.own.mechanism.kind == "parallel" else None
            others = []
            if truth is not None and hasattr(er.own.mechanism, "fk_exact"):
                sols = np.atleast_2d(er.own.mechanism.fk_exact(rec.case.inputs))
                others = [sol for sol in sols if np.max(np.abs(sol - truth)) > 1e-6 and er.own.mechanism.in_bounds(sol)]
            for ax, (i, j, k) in zip(row, ((0, 1, 2), (0, 2, 1))):
                gi, gj, z = _shading(rec.problem, b, i, j, k)
                im = ax.pcolormesh(gi, gj, z, cmap="Greys_r", shading="auto", rasterized=True)
                ax.scatter(pts[:, i], pts[:, j], s=7, marker="o", color="tab:orange", lw=0, label="ants")
                if truth is not None:
                    ax.plot(truth[i], truth[j], marker="*", ms=12, color="tab:red", ls="none", mec="k", mew=0.5,
                            label="true pose")
                for n_o, sol in enumerate(others):
                    ax.plot(sol[i], sol[j], marker="D", ms=7, color="tab:cyan", ls="none", mec="k", mew=0.5,
                            label="mirror solution (same inputs)" if n_o == 0 else None)
                ax.set_xlim(*b[i])
                ax.set_ylim(*b[j])
                ax.set_xlabel(f"{names[i]} ({units[i]})")
                ax.set_ylabel(f"{names[j]} ({units[j]})")
                ax.grid(False)
                fig.colorbar(im, ax=ax, label=f"log10 of f, minimised over {names[k]}")
            row[0].legend(loc="upper left", fontsize=7, frameon=True)
            row[0].set_title(f"{names_of[rec.spec.key]}, case {rec.case.label}: {t} moves (run 0)")
        fig.tight_layout()
        written += _save(fig, folder / figure_file(er, f"snapshot_{t}"))
        plt.close(fig)
    return written


def extras_figure(er: RunResult, folder: Path, tables: dict) -> list[str]:
    """Median over runs of each algorithm record vs iteration (wu2015 Fig. 7). Pheromone is
    tau = -f <= 0, so it is drawn as -tau on a log axis (the best pheromone's -tau is the best f)."""
    if not er.own.solves:
        return []
    recs = [r for r in er.own.solves if r.case.index == 0 and r.result.extras]
    if "extras" not in er.config.figures or not recs:
        return []
    path = folder / figure_file(er, "extras")
    plt = _plt()
    names = _spec_names(er)
    keys = sorted({k for r in recs for k in r.result.extras})
    fig, axes = plt.subplots(1, len(keys), figsize=(4.2 * len(keys), 3.4), squeeze=False)
    unit = plotting.fitness_label(er.own.mechanism, getattr(recs[0].problem, "objective", None)).split("(")[-1].rstrip(")")
    for rec in recs:
        for ax, k in zip(axes[0], keys):
            if k not in rec.result.extras:
                continue
            v = rec.result.extras[k]
            neg = k.startswith("pheromone") and np.all(v <= 0)
            y = -v if neg else v
            floor = plotting.floor_of(y)
            label = names[rec.spec.key] + ("" if v.shape[0] == 1 else f" (median of {v.shape[0]} runs)")
            ax.plot(np.arange(v.shape[1]), np.maximum(np.median(y, axis=0), floor), label=label)
            if np.all(y >= 0):
                ax.set_yscale("log")
            what = k.replace("pheromone_", "").replace("_", " ")
            ax.set_title(f"{what} pheromone τ, drawn as −τ" if neg else k)
            ax.set_ylabel(f"−τ_{what} ({unit})" if neg else k)
            ax.set_xlabel("colony move (iteration)")
    plotting.legend_off_data(axes[0][-1], source=axes[0][0])
    fig.suptitle(f"{er.config.title or er.config.name}: case {recs[0].case.label}", fontsize=9)
    fig.tight_layout()
    out = _save(fig, path)
    plt.close(fig)
    return out


def position_error_figure(er: RunResult, folder: Path, tables: dict) -> list[str]:
    """Best-so-far position error (the arm's length unit) vs iteration (wang7dof Figs. 5/6a), serial arms."""
    curves = [c for c in _curve_sets(er) if c[4] is not None] if er.own.mechanism.kind == "serial" else []
    if not curves:
        return []
    path = folder / figure_file(er, "position_error")
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    floor = plotting.floor_of(*[c[4] for c in curves])
    for name, _, _, _, pos, _ in curves:
        _band(ax, np.arange(pos.shape[1]), pos, floor, name)
    ax.set_yscale("log")
    if any(bool((c[4] <= 0).any()) for c in curves):
        plotting.mark_zero(ax, floor)
    ax.set_xlabel("iteration")
    runs = curves[0][4].shape[0]
    ax.set_ylabel(f"position error of the best-so-far ({plotting.position_unit(er.own.mechanism)})")
    ax.set_title(f"{er.config.title or er.config.name}\n"
                 + ("one run" if runs == 1 else f"median of {runs} runs, band: quartiles"), fontsize=9)
    plotting.legend_off_data(ax)
    out = _save(fig, path)
    plt.close(fig)
    return out


def _case_axis(ax, n: int) -> None:
    ax.set_xlabel("pose (case index)")
    ax.set_xlim(0.3, n + 0.7)


def cases_figures(er: RunResult, folder: Path, tables: dict) -> list[str]:
    """Per case (independent poses: markers, no lines): final fitness (deterministic), time per run
    (timed single runs) and, for serial arms, the final position error (wang7dof Fig. 7)."""
    if not er.own.solves:
        return []
    if "cases" not in er.config.figures:
        return []
    summary, timing = tables["summary.csv"], tables.get("timing.csv")
    plt = _plt()
    names = _spec_names(er)
    markers = "osD^v<>"
    runs = er.config.runs
    agg = "median over runs of the " if runs > 1 else ""
    written = []
    fit_label = plotting.fitness_label(er.own.mechanism, getattr(er.own.solves[0].problem, "objective", None))
    order = {c.label: c.index + 1 for c in er.own.cases}
    panels = [("cases", summary, "median_fitness", f"{agg}final {fit_label}", True)]
    if timing is not None and len(timing):
        panels.append(("cases_time", timing, "median_ms_per_run", "time per run, one run at a time (ms)", False))
    for kind, table, col, ylabel, log in panels:
        fig, ax = plt.subplots(figsize=(7, 3.4))
        floor = plotting.floor_of(table[col].to_numpy(float)) if log else None
        for n, (algo, grp) in enumerate(table.groupby("algorithm", sort=False)):
            x = grp["case"].map(order).to_numpy(float)
            y = grp[col].to_numpy(dtype=float)
            ax.plot(x, np.maximum(y, floor) if log else y, ls="none", marker=markers[n % len(markers)], ms=4,
                    label=names.get(algo, algo))
        if log:
            ax.set_yscale("log")
            if (table[col] <= 0).any():
                plotting.mark_zero(ax, floor)
        else:             # times on a linear axis from 0: a 32 vs 80 ms gap is not drawn as 1 to 25
            ax.set_ylim(bottom=0)
        shown = int(table["case"].map(order).max())   # timings cover only the first timed cases
        _case_axis(ax, shown)
        ax.set_ylabel(ylabel)
        ax.set_title((er.config.title or er.config.name)
                     + (f"\ntimed poses only: the first {shown} of {len(er.own.cases)}" if shown < len(er.own.cases) else ""),
                     fontsize=9)
        plotting.legend_off_data(ax)
        written += _save(fig, folder / figure_file(er, kind))
        plt.close(fig)
    if er.own.mechanism.kind == "serial":   # wang7dof Fig. 7a: final position error per pose
        fig, ax = plt.subplots(figsize=(7, 3.4))
        ys = []
        for n, spec in enumerate(one_answer_entries(er.config)):
            recs = [r for r in er.own.solves if r.spec.key == spec.key and r.position_error_history is not None]
            if recs:
                y = np.array([float(np.median(r.position_error_history[:, -1])) for r in recs])
                ys.append(y)
                ax.plot([r.case.index + 1 for r in recs], y, ls="none", marker=markers[n % len(markers)], ms=4,
                        label=names[spec.key])
        floor = plotting.floor_of(*ys)
        for line in ax.get_lines():
            line.set_ydata(np.maximum(line.get_ydata(), floor))
        ax.set_yscale("log")
        _case_axis(ax, len(er.own.cases))
        ax.set_ylabel(f"{agg}final position error ({plotting.position_unit(er.own.mechanism)})")
        ax.set_title(er.config.title or er.config.name, fontsize=9)
        plotting.legend_off_data(ax)
        written += _save(fig, folder / figure_file(er, "cases_position_error"))
        plt.close(fig)
    return written


def time_figure(er: RunResult, folder: Path, tables: dict) -> list[str]:
    """Time of every timed single run per algorithm (wang7dof Fig. 6b): points and their median."""
    alone = er.timing[er.timing["mode"] == record.ALONE] if er.timing is not None else None
    if "time" not in er.config.figures or alone is None or alone.empty:
        return []
    path = folder / figure_file(er, "time")
    plt = _plt()
    names = _spec_names(er)
    fig, ax = plt.subplots(figsize=(5, 3.4))
    timed = one_answer_entries(er.config)
    for n, spec in enumerate(timed):
        ms = alone.loc[alone["solver"] == spec.key, "seconds"].to_numpy(float) * 1e3
        x = n + np.linspace(-0.15, 0.15, len(ms)) if len(ms) > 1 else np.array([float(n)])
        ax.plot(x, ms, ls="none", marker="o", ms=4, alpha=0.7)
        ax.plot([n - 0.25, n + 0.25], [np.median(ms)] * 2, color="k", lw=1.5)
    ax.set_xticks(range(len(timed)), [names[s.key] for s in timed])
    ax.set_ylabel("time per run, one run at a time (ms)")
    ax.set_ylim(bottom=0)                  # from 0: the ratio of two times is the ratio of their heights
    ax.set_title(f"{er.config.title or er.config.name}\n{len(ms)} of the {er.config.runs} runs per algorithm "
                 "timed one at a time (fkopt's timing sample, TIMING.md; bar: median)", fontsize=9)
    out = _save(fig, path)
    plt.close(fig)
    return out


# -- folder --------------------------------------------------------------------------------------
def meta(er: RunResult) -> dict:
    """What the config and the seed fix (nothing about the machine: that is :func:`environment`)."""
    seeds = er.record.groupby(["pose", "solver"], sort=False)["task_seed"].first() if er.record is not None else {}
    return {
        "experiment": er.config.name, "paper": er.config.paper, "title": er.config.title,
        "config_file": er.source, "config": er.config.model_dump(mode="json"),
        "seed": er.config.seed,
        "task_seeds": [{"case": r.case.label, "algorithm": r.spec.key, "seed": int(seeds[(r.case.index, r.spec.key)])}
                       for r in er.own.solves] + [{"case": s.case.label, "algorithm": s.spec.key, "seed": s.seed}
                                                  for s in er.own.sets],
        "mechanism": er.own.mechanism.describe(),
        "objective": getattr(er.own.solves[0].problem, "objective", None) if er.own.solves else None,
    }


def console(er: RunResult, folder) -> pd.DataFrame | list[str]:
    """What ``fkopt run`` prints: the summary table, or (only ``solutions: all`` entries) the
    count of solutions per case and entry."""
    summary = summary_table(er)
    if summary is not None:
        return summary
    return [""] + [f"  {s.case.label} · {s.spec.key}: {len(s.found.values)} solution(s), "
                   f"{s.found.search.get('starts')} starts (solutions.csv)" for s in er.own.sets]


def write_tables(er: RunResult, folder: Path, figures: bool = True) -> list[str]:
    """Every file of the experiment (:data:`fkopt.run.writers.OUTPUTS`) into ``folder`` (which must exist)."""
    return write_outputs("experiment", er, folder, figures=figures)


def write_experiment(er: RunResult, out: Path) -> Path:
    """Write the experiment's folder aside, then swap it into place."""
    return write_result("experiment", er, out)
