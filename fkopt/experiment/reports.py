"""Reports: turn an :class:`ExperimentResult` into CSV tables, figures and ``meta.json``.

Files of one experiment folder (all deterministic for a given seed except ``timing.csv`` and
the figures drawn from timings, ``cases_time.png``):

* ``summary.csv``     final fitness statistics per case and algorithm over all runs (mean, std,
  best, worst, median), evaluations, success rate and iterations/evaluations to the threshold
  (medians over the runs that reached it), the paper's printed values beside them;
* ``timing.csv``      mean/median time per run (ms; amortised over the batch) beside the printed time;
* ``values.csv``      per variable: target, the median run's value and error (the run whose final
  fitness is the lower median), the best run's, and the mean absolute error over all runs;
* ``inputs.csv``      (only when a case gives both joints and a pose) given vs computed inputs;
* ``runs.csv``        one row per run (incl. ``iterations_to_best``: first iteration at which the
  run's final best-so-far fitness was reached);
* ``convergence.csv`` best-so-far fitness per iteration: median and quartiles over runs, mean
  evaluations; ``convergence.png`` the same on a log scale (vs iterations and vs evaluations);
* optional figures (``figures:`` in the config): ``variables.png``, ``snapshot_<t>.png``,
  ``extras.png``, ``cases.png`` + ``cases_time.png`` (+ ``cases_position_error.png`` for
  serial arms), ``position_error.png``;
* ``meta.json``       config, seeds, fkopt/library versions, platform.

A folder is written into a temporary sibling first and renamed into place, so a failed or
interrupted run never leaves a half-written results folder.
"""
from __future__ import annotations

import json
import os
import platform
import shutil
import sys
import tempfile
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import numpy as np
import pandas as pd

from .runner import ExperimentResult, pose_error

FLOAT = "%.10g"
#: Fitness of exactly 0 cannot be drawn on a log axis; it is drawn at this floor (and said so).
LOG_FLOOR = 1e-32
#: Beyond this many cases, convergence curves are pooled over all (case, run) pairs.
MAX_CASE_CURVES = 6
LIBRARIES = ("numpy", "scipy", "pandas", "matplotlib", "pydantic", "pyyaml", "typer", "rich", "pymoo", "niapy",
             "yourdfpy")


def _nanmedian(a) -> float:
    a = np.asarray(a, dtype=float)
    return float(np.median(a[~np.isnan(a)])) if np.any(~np.isnan(a)) else float("nan")


# -- tables ------------------------------------------------------------------------------------
def summary_table(er: ExperimentResult) -> pd.DataFrame:
    thr = er.config.threshold
    rows = []
    for rec in er.records:
        r, spec = rec.result, rec.spec
        row = {
            "case": rec.case.label, "algorithm": spec.key, "method": spec.name,
            "population": r.population, "iterations": r.iterations, "runs": r.runs,
            "mean_fitness": float(np.mean(r.fitness)), "std_fitness": float(np.std(r.fitness, ddof=1)) if r.runs > 1 else 0.0,
            "best_fitness": float(np.min(r.fitness)), "worst_fitness": float(np.max(r.fitness)),
            "median_fitness": float(np.median(r.fitness)),
            "mean_evaluations": float(np.mean(r.evaluations)),
            "threshold": thr,
        }
        if thr is not None:
            row["success_rate"] = float(np.mean(r.success(thr)))
            row["median_iterations_to_threshold"] = _nanmedian(r.iterations_to(thr))
            row["median_evaluations_to_threshold"] = _nanmedian(r.evaluations_to(thr))
        for k, v in spec.printed.items():
            if not k.endswith("_ms"):
                row[f"printed_{k}"] = v
        rows.append(row)
    return pd.DataFrame(rows)


def timing_table(er: ExperimentResult) -> pd.DataFrame:
    rows = []
    for rec in er.records:
        t = rec.result.time_per_run * 1e3
        row = {"case": rec.case.label, "algorithm": rec.spec.key, "runs": rec.result.runs,
               "batch": er.config.batch, "mean_ms_per_run": float(np.mean(t)),
               "median_ms_per_run": float(np.median(t)), "total_s": rec.wall_s}
        for k, v in rec.spec.printed.items():
            if k.endswith("_ms"):
                row[f"printed_{k}"] = v
        rows.append(row)
    return pd.DataFrame(rows)


def values_table(er: ExperimentResult) -> pd.DataFrame:
    mech = er.mechanism
    rows = []
    for rec in er.records:
        r, case = rec.result, rec.case
        med, best = r.median_run, r.best_run
        target = case.target if case.target is not None else case.reference
        printed = case.printed.get(rec.spec.key, {})
        for j, (name, unit) in enumerate(zip(er.compared_names, er.compared_units)):
            row = {"case": case.label, "algorithm": rec.spec.key, "variable": name, "unit": unit,
                   "target": float(target[j]) if target is not None else np.nan,
                   "median_run": int(r.run_ids[med]), "median_run_value": float(rec.outputs[med, j]),
                   "best_run_value": float(rec.outputs[best, j])}
            if target is not None:
                err = pose_error(mech, rec.outputs, target)[:, j]
                row["median_run_abs_error"] = float(err[med])
                row["best_run_abs_error"] = float(err[best])
                row["mean_abs_error"] = float(np.mean(err))
            if case.reference is not None:
                row[case.reference_label] = float(case.reference[j])
                row[f"median_run_error_vs_{case.reference_label}"] = float(
                    pose_error(mech, rec.outputs[med], case.reference)[j])
            if name in printed:
                row["printed_value"] = printed[name]
                if target is not None:
                    row["printed_abs_error"] = _abs_diff(unit, printed[name], float(target[j]))
            rows.append(row)
    return pd.DataFrame(rows)


def _abs_diff(unit: str, a: float, b: float) -> float:
    d = a - b
    return float(abs((d + 180.0) % 360.0 - 180.0) if unit == "deg" else abs(d))


def inputs_table(er: ExperimentResult) -> pd.DataFrame | None:
    mech = er.mechanism
    rows = []
    for case in er.cases:
        if case.given_joints is None or case.joints_from_pose is None:
            continue
        for name, unit, g, c in zip(mech.joint_names, mech.joint_units, case.given_joints, case.joints_from_pose):
            rows.append({"case": case.label, "joint": name, "unit": unit, "given": float(g),
                         "from_nominal_pose": float(c), "difference": float(g - c)})
    return pd.DataFrame(rows) if rows else None


def runs_table(er: ExperimentResult) -> pd.DataFrame:
    thr = er.config.threshold
    frames = []
    for rec in er.records:
        r = rec.result
        df = pd.DataFrame({"case": rec.case.label, "algorithm": rec.spec.key, "run": r.run_ids,
                           "task_seed": rec.seed, "final_fitness": r.fitness, "evaluations": r.evaluations,
                           "iterations_done": r.iterations_done,
                           # first iteration at which the run's final best-so-far fitness was reached
                           "iterations_to_best": np.argmax(r.history <= r.history[:, -1:], axis=1)})
        if thr is not None:
            df["iterations_to_threshold"] = r.iterations_to(thr)
            df["evaluations_to_threshold"] = r.evaluations_to(thr)
        for j, name in enumerate(r.variable_names):
            df[f"x_{name}"] = r.x[:, j]
        if er.mechanism.kind == "serial":
            for j, name in enumerate(er.compared_names):
                df[f"pose_{name}"] = rec.outputs[:, j]
        if rec.position_error_history is not None:
            df["position_error"] = rec.position_error_history[:, -1]
        case = rec.case
        target = case.target if case.target is not None else case.reference
        if target is not None:
            err = pose_error(er.mechanism, rec.outputs, target)
            for j, name in enumerate(er.compared_names):
                df[f"abs_error_{name}"] = err[:, j]
        for key in r.extras:
            df[f"final_{key}"] = r.extras[key][:, -1]
        frames.append(df)
    return pd.concat(frames, ignore_index=True)


def convergence_table(er: ExperimentResult) -> pd.DataFrame:
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


def _curves(er: ExperimentResult):
    """(case label, algorithm, history, evaluation history, position error history) per curve."""
    pooled = len(er.cases) > MAX_CASE_CURVES
    if not pooled:
        for rec in er.records:
            yield (rec.case.label, rec.spec.key, rec.result.history, rec.result.evaluation_history,
                   rec.position_error_history)
        return
    for spec in er.config.algorithms:
        recs = [r for r in er.records if r.spec.key == spec.key]
        pos = [r.position_error_history for r in recs]
        yield ("all", spec.key, np.concatenate([r.result.history for r in recs]),
               np.concatenate([r.result.evaluation_history for r in recs]),
               np.concatenate(pos) if pos[0] is not None else None)


# -- figures -------------------------------------------------------------------------------------
def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.rcParams.update({"figure.dpi": 110, "font.size": 9, "svg.hashsalt": "fkopt"})
    return plt


def _save(fig, path: Path) -> None:
    # Fixed metadata so that a rerun writes a byte-identical PNG.
    fig.savefig(path, metadata={"Software": None}, bbox_inches="tight")


def convergence_figure(er: ExperimentResult, path: Path) -> None:
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    zero = False
    for label, algo, hist, evals, _ in _curves(er):
        name = algo if len(er.cases) == 1 else f"{algo} · {label}"
        zero |= bool((hist <= 0).any())
        h = np.maximum(hist, LOG_FLOOR)
        q25, med, q75 = np.percentile(h, [25, 50, 75], axis=0)
        it = np.arange(h.shape[1])
        ev = evals.mean(axis=0)
        for ax, xs in zip(axes, (it, ev)):
            line, = ax.plot(xs, med, label=name, lw=1.4)
            ax.fill_between(xs, q25, q75, color=line.get_color(), alpha=0.2, lw=0)
    for ax, xl in zip(axes, ("iteration", "function evaluations (mean over runs)")):
        ax.set_yscale("log")
        ax.set_xlabel(xl)
        ax.grid(True, which="major", alpha=0.3)
    axes[0].set_ylabel("best-so-far fitness (median, IQR band)")
    axes[0].legend(fontsize=7)
    title = er.config.title or er.config.name
    if zero:
        title += f"  (fitness 0 drawn at {LOG_FLOOR:g})"
    fig.suptitle(title, fontsize=10)
    _save(fig, path)
    plt.close(fig)


def variables_figure(er: ExperimentResult, path: Path) -> None:
    """Best-so-far value of each unknown vs iteration for the median run (liu2008 Fig. 4a)."""
    plt = _plt()
    recs = [r for r in er.records if r.case.index == 0]
    names = recs[0].result.variable_names
    fig, axes = plt.subplots(1, len(names), figsize=(2.6 * len(names), 3), squeeze=False)
    for rec in recs:
        r = rec.result
        xh = r.x_history[r.median_run]
        for j, ax in enumerate(axes[0]):
            ax.plot(np.arange(xh.shape[0]), xh[:, j], label=rec.spec.key)
            ax.set_title(names[j])
            ax.set_xlabel("iteration")
    if recs[0].case.target is not None and er.mechanism.kind == "parallel":
        for j, ax in enumerate(axes[0]):
            ax.axhline(recs[0].case.target[j], color="k", lw=0.8, ls="--")
    axes[0][0].legend(fontsize=7)
    fig.suptitle(f"{er.config.title or er.config.name}: best-so-far variables (median run)", fontsize=10)
    fig.tight_layout()
    _save(fig, path)
    plt.close(fig)


def snapshot_figures(er: ExperimentResult, folder: Path) -> list[str]:
    """Population scatter at the snapshot iterations, first case, run 0 (wu2015 Figs. 4-6)."""
    plt = _plt()
    written = []
    recs = [r for r in er.records if r.case.index == 0]
    for t in er.config.snapshots:
        fig = plt.figure(figsize=(4.5 * len(recs), 4))
        for i, rec in enumerate(recs):
            if t not in rec.result.snapshots:
                continue
            pts = rec.result.snapshots[t][0]
            names = rec.result.variable_names
            b = rec.problem.bounds
            if pts.shape[1] >= 3:
                ax = fig.add_subplot(1, len(recs), i + 1, projection="3d")
                ax.scatter(pts[:, 0], pts[:, 1], pts[:, 2], s=8, marker="*")
                if rec.case.target is not None and er.mechanism.kind == "parallel":
                    ax.scatter(*rec.case.target[:3], s=60, c="r", marker="o")
                ax.set_zlim(*b[2])
                ax.set_zlabel(names[2])
            else:
                ax = fig.add_subplot(1, len(recs), i + 1)
                ax.scatter(pts[:, 0], pts[:, 1], s=8, marker="*")
            ax.set_xlim(*b[0])
            ax.set_ylim(*b[1])
            ax.set_xlabel(names[0])
            ax.set_ylabel(names[1])
            ax.set_title(f"{rec.spec.key}: iteration {t}", fontsize=9)
        name = f"snapshot_{t}.png"
        _save(fig, folder / name)
        plt.close(fig)
        written.append(name)
    return written


def extras_figure(er: ExperimentResult, path: Path) -> bool:
    """Median over runs of each algorithm extra record vs iteration (wu2015 Fig. 7)."""
    recs = [r for r in er.records if r.case.index == 0 and r.result.extras]
    if not recs:
        return False
    plt = _plt()
    keys = sorted({k for r in recs for k in r.result.extras})
    fig, axes = plt.subplots(1, len(keys), figsize=(4.5 * len(keys), 3.5), squeeze=False)
    for rec in recs:
        for ax, k in zip(axes[0], keys):
            if k in rec.result.extras:
                v = rec.result.extras[k]
                ax.plot(np.arange(v.shape[1]), np.median(v, axis=0), label=rec.spec.key)
                ax.set_title(k)
                ax.set_xlabel("iteration")
                if np.all(v > 0) or np.all(v < 0):
                    ax.set_yscale("symlog" if np.any(v < 0) else "log", **({"linthresh": 1e-12} if np.any(v < 0) else {}))
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    _save(fig, path)
    plt.close(fig)
    return True


def position_error_figure(er: ExperimentResult, path: Path) -> bool:
    """Best-so-far position error vs iteration (wang7dof Figs. 5/6)."""
    curves = [c for c in _curves(er) if c[4] is not None]
    if not curves:
        return False
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for label, algo, _, _, pos in curves:
        p = np.maximum(pos, LOG_FLOOR)
        q25, med, q75 = np.percentile(p, [25, 50, 75], axis=0)
        line, = ax.plot(np.arange(p.shape[1]), med, label=algo if label in ("all",) or len(er.cases) == 1 else f"{algo} · {label}")
        ax.fill_between(np.arange(p.shape[1]), q25, q75, color=line.get_color(), alpha=0.2, lw=0)
    ax.set_yscale("log")
    ax.set_xlabel("iteration")
    ax.set_ylabel("position error of best-so-far (median, IQR)")
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    _save(fig, path)
    plt.close(fig)
    return True


def cases_figures(er: ExperimentResult, folder: Path, summary: pd.DataFrame, timing: pd.DataFrame) -> list[str]:
    """Per-case median final fitness (deterministic) and time per run (timing) figures."""
    plt = _plt()
    written = []
    for name, table, col, ylabel in (("cases.png", summary, "median_fitness", "median final fitness"),
                                     ("cases_time.png", timing, "median_ms_per_run", "time per run (ms)")):
        fig, ax = plt.subplots(figsize=(7, 3.5))
        for algo, grp in table.groupby("algorithm", sort=False):
            y = grp[col].to_numpy(dtype=float)
            ax.plot(np.arange(1, len(y) + 1), np.maximum(y, LOG_FLOOR) if col.endswith("fitness") else y,
                    marker="o", ms=3, lw=0.8, label=algo)
        if col.endswith("fitness"):
            ax.set_yscale("log")
        ax.set_xlabel("case")
        ax.set_ylabel(ylabel)
        ax.legend(fontsize=7)
        ax.grid(True, alpha=0.3)
        _save(fig, folder / name)
        plt.close(fig)
        written.append(name)
    if er.mechanism.kind == "serial":   # wang7dof Fig. 7a: final position error per pose
        fig, ax = plt.subplots(figsize=(7, 3.5))
        for spec in er.config.algorithms:
            y = [float(np.median(r.position_error_history[:, -1])) for r in er.records
                 if r.spec.key == spec.key and r.position_error_history is not None]
            if y:
                ax.plot(np.arange(1, len(y) + 1), np.maximum(y, LOG_FLOOR), marker="o", ms=3, lw=0.8,
                        label=spec.key)
        ax.set_yscale("log")
        ax.set_xlabel("case")
        ax.set_ylabel("median final position error")
        ax.legend(fontsize=7)
        ax.grid(True, alpha=0.3)
        _save(fig, folder / "cases_position_error.png")
        plt.close(fig)
        written.append("cases_position_error.png")
    return written


# -- folder --------------------------------------------------------------------------------------
def library_versions() -> dict[str, str]:
    out = {"python": sys.version.split()[0]}
    for lib in LIBRARIES:
        try:
            out[lib] = version(lib)
        except PackageNotFoundError:
            pass
    return out


def meta(er: ExperimentResult) -> dict:
    from .. import __version__
    return {
        "experiment": er.config.name, "paper": er.config.paper, "title": er.config.title,
        "config_file": er.source, "config": er.config.model_dump(mode="json"),
        "seed": er.config.seed,
        "task_seeds": [{"case": r.case.label, "algorithm": r.spec.key, "seed": r.seed} for r in er.records],
        "mechanism": er.mechanism.describe(),
        "objective": getattr(er.records[0].problem, "objective", None),
        "fkopt_version": __version__, "libraries": library_versions(),
        "platform": {"system": platform.system(), "machine": platform.machine(),
                     "python_implementation": platform.python_implementation()},
    }


def write_tables(er: ExperimentResult, folder: Path) -> list[str]:
    """Write every file of the experiment into ``folder`` (which must exist); returns the names."""
    folder = Path(folder)
    written = []

    def csv(name, df):
        if df is not None:
            df.to_csv(folder / name, index=False, float_format=FLOAT)
            written.append(name)

    summary, timing = summary_table(er), timing_table(er)
    csv("summary.csv", summary)
    csv("timing.csv", timing)
    csv("values.csv", values_table(er))
    csv("inputs.csv", inputs_table(er))
    csv("runs.csv", runs_table(er))
    csv("convergence.csv", convergence_table(er))
    from .traces import write_trace   # each run's best-so-far improvements (fkopt export)
    written.append(write_trace(er, folder))
    convergence_figure(er, folder / "convergence.png")
    written.append("convergence.png")
    figs = set(er.config.figures)
    if "variables" in figs:
        variables_figure(er, folder / "variables.png")
        written.append("variables.png")
    if "snapshots" in figs:
        written += snapshot_figures(er, folder)
    if "extras" in figs and extras_figure(er, folder / "extras.png"):
        written.append("extras.png")
    if "cases" in figs:
        written += cases_figures(er, folder, summary, timing)
    if er.mechanism.kind == "serial" and position_error_figure(er, folder / "position_error.png"):
        written.append("position_error.png")
    (folder / "meta.json").write_text(json.dumps(meta(er), indent=2, sort_keys=True, default=float) + "\n")
    written.append("meta.json")
    return written


def experiment_folder(out: Path, er_or_config) -> Path:
    config = getattr(er_or_config, "config", er_or_config)
    return Path(out) / (config.paper or "experiments") / config.name


def write_atomically(final: Path, write) -> Path:
    """Call ``write(tmp)`` on a temporary sibling folder of ``final``, then rename it into place.

    A failed or interrupted write leaves ``final`` as it was (old results or nothing), never
    half-written.
    """
    final = Path(final)
    final.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{final.name}.", dir=final.parent))
    try:
        write(tmp)
        if final.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{final.name}.old.", dir=final.parent))
            os.replace(final, old / "x")
            os.replace(tmp, final)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, final)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return final


def write_experiment(er: ExperimentResult, out: Path) -> Path:
    """Write the experiment's folder atomically (see :func:`write_atomically`)."""
    return write_atomically(experiment_folder(out, er), lambda tmp: write_tables(er, tmp))
