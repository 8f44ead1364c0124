"""Files of a study folder ``OUT/<paper>/<name>/`` (conventions of :mod:`fkopt.kinds.experiment.reports`).

The makers below are listed with their roles in :data:`fkopt.run.writers.OUTPUTS` (``study``) and
written by :func:`fkopt.run.writers.write_outputs`; a maker returns None (a table) or ``[]`` (a
figure) when its file does not apply (no grid, not tracking).

Deterministic for a given config (whatever the executor, the number of jobs or a resume):

* ``summary.csv``  one row per algorithm over all (pose, run) pairs (``case`` is ``all``, or
  ``trajectory`` in tracking mode) with the columns of an experiment's summary (fitness
  statistics, mean evaluations, success rate at the threshold, medians of iterations and
  evaluations to it over the pairs that reached it) plus ``poses``; so ``fkopt report`` and
  ``fkopt check`` read it like an experiment's;
* ``poses.csv``    one row per (pose, algorithm): the pose, median/best final fitness, success
  rate over the runs, median evaluations to the threshold, median absolute error per variable;
* ``runs.csv``     one row per (pose, algorithm, run), with the start point in tracking mode;
* ``ecdf.csv`` + ``ecdf.png``  fraction of (pose, run) pairs solved vs evaluations (log x);
* ``stats.csv``    pairwise Wilcoxon rank-sum tests with Holm's correction
  (:mod:`fkopt.kinds.study.statistics`);
* ``heatmap.csv`` + ``heatmap.png``  (a grid over two variables) median final fitness and
  success rate per grid point and algorithm;
* ``tracking.csv`` + ``tracking.png``  (tracking mode) per step and algorithm: median fitness,
  success rate, evaluations, largest error, whether the step was warm-started;
* ``meta.json``    config, seed, seed rule, mechanism, digests of the CSVs (written last);
  ``env.json`` -- versions and platform (:mod:`fkopt.run.provenance`), like the timing files.

Measured in seconds (change on every run): ``timing.csv`` (per algorithm, time per run) and,
in tracking mode, ``tracking_timing.csv`` + ``tracking_time.png`` (time per step).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from types import SimpleNamespace

from fkopt.run import record
from fkopt.run import plotting
from fkopt.run.result import RunResult
from fkopt.run.plotting import plt as _plt, save as _save
from fkopt.files import nanmedian as _nanmedian
from fkopt.kinds.study.statistics import ecdf_table, pairwise_tests
from fkopt.problems import fk_problem, ik_problem


def _algorithms(sr: RunResult) -> list[SimpleNamespace]:
    """Per algorithm (config order), its columns of the run record as (pose, run) arrays and its
    per-pose times from the timing record: the views the per-pose tables and figures read."""
    n, runs = len(sr.own.poses), sr.config.runs
    out = []
    for spec in sr.config.algorithms:
        mine = sr.record[sr.record["solver"] == spec.key]
        per_pose = lambda col: mine[col].to_numpy(float).reshape(n, runs)   # noqa: E731
        errors = np.stack([per_pose(f"abs_error_{name}") for name in sr.own.mechanism.pose_names], axis=-1)
        out.append(SimpleNamespace(
            key=spec.key, spec=spec, population=spec.population or sr.config.population,
            iterations=spec.iterations or sr.config.iterations, fitness=per_pose("final_fitness"),
            evaluations=per_pose("evaluations"), evaluations_to=per_pose("evaluations_to_threshold"), errors=errors,
            time_s=sr.timing.loc[sr.timing["solver"] == spec.key, "seconds"].to_numpy(float),
            wall_s=sr.own.solve_s[spec.key]))
    return out


def case_label(sr: RunResult) -> str:
    return "trajectory" if sr.config.mode == "tracking" else "all"


# -- tables --------------------------------------------------------------------------------------
def summary_table(sr: RunResult) -> pd.DataFrame:
    """Per algorithm over every (pose, run) (the one summary writer, :func:`fkopt.run.record.summary_table`)."""
    settings = {ar.key: {"method": ar.spec.name, "population": ar.population, "iterations": ar.iterations,
                         "runs": sr.config.runs} for ar in _algorithms(sr)}
    return record.summary_table(sr.record, settings, sr.config.threshold, by=("solver",), case=case_label(sr),
                                extra={"poses": len(sr.own.poses)})


def _pose_columns(sr: RunResult, i: np.ndarray | int) -> dict:
    cols = {f"{n}": sr.own.poses.points[i, j] for j, n in enumerate(sr.own.poses.names)}
    if sr.own.mechanism.kind == "serial":
        cols.update({f"target_{n}": sr.own.poses.targets[i, j] for j, n in enumerate(sr.own.mechanism.pose_names)})
    return cols


def poses_table(sr: RunResult) -> pd.DataFrame:
    thr = sr.config.threshold
    n = len(sr.own.poses)
    idx = np.arange(n)
    frames = []
    for ar in _algorithms(sr):
        med_ev = np.array([_nanmedian(row) for row in ar.evaluations_to])
        df = pd.DataFrame({"pose": idx, "label": [sr.own.poses.label(i) for i in idx], **_pose_columns(sr, idx),
                           "algorithm": ar.key, "median_fitness": np.median(ar.fitness, axis=1),
                           "best_fitness": np.min(ar.fitness, axis=1),
                           "success_rate": np.mean(ar.fitness < thr, axis=1),
                           "median_evaluations_to_threshold": med_ev,
                           "mean_evaluations": np.mean(ar.evaluations, axis=1)})
        for j, name in enumerate(sr.own.mechanism.pose_names):
            df[f"median_abs_error_{name}"] = np.median(ar.errors[:, :, j], axis=1)
        frames.append(df)
    return pd.concat(frames, ignore_index=True)


def timing_table(sr: RunResult) -> pd.DataFrame:
    """Per algorithm, ms per run of each pose (its share of the batch; the one timing writer,
    :func:`fkopt.run.record.timing_table`)."""
    settings = {(case_label(sr), ar.key): {"runs": sr.config.runs, "poses": len(sr.own.poses), "total_s": float(ar.wall_s)}
                for ar in _algorithms(sr)}
    return record.timing_table(sr.timing, settings, names=record.ALGORITHM_NAMES)


def _per_algorithm(sr: RunResult, column: str) -> dict[str, np.ndarray]:
    """A run-record column pooled over every (pose, run) of each algorithm, in config order."""
    return {key: g[column].to_numpy(float) for key, g in sr.record.groupby("solver", sort=False)}


def ecdf_of(sr: RunResult) -> pd.DataFrame:
    """Fraction of (pose, run) pairs solved vs evaluations, from the run record."""
    return ecdf_table(_per_algorithm(sr, "evaluations_to_threshold"))


def stats_of(sr: RunResult) -> pd.DataFrame:
    """Pairwise rank tests over the run record's (pose, run) samples (Holm per metric)."""
    samples = {metric: _per_algorithm(sr, metric) for metric in ("final_fitness", "evaluations_to_threshold")}
    return pairwise_tests(samples, sr.config.alpha)


def heatmap_table(sr: RunResult) -> pd.DataFrame | None:
    axes = sr.own.poses.grid_axes
    if axes is None:
        return None
    names = sr.own.poses.names
    j1, j2 = names.index(axes[0]), names.index(axes[1])
    thr = sr.config.threshold
    frames = []
    for ar in _algorithms(sr):
        frames.append(pd.DataFrame({
            axes[0]: sr.own.poses.points[:, j1], axes[1]: sr.own.poses.points[:, j2], "algorithm": ar.key,
            "median_fitness": np.median(ar.fitness, axis=1), "success_rate": np.mean(ar.fitness < thr, axis=1),
            "median_evaluations_to_threshold": [_nanmedian(row) for row in ar.evaluations_to],
            **{f"median_abs_error_{n}": np.median(ar.errors[:, :, j], axis=1)
               for j, n in enumerate(sr.own.mechanism.pose_names)}}))
    return pd.concat(frames, ignore_index=True)


def tracking_table(sr: RunResult) -> pd.DataFrame | None:
    if sr.config.mode != "tracking":
        return None
    thr = sr.config.threshold
    step = sr.own.poses.step
    frames = []
    for ar in _algorithms(sr):
        warm = (step > 0) & ar.spec.warm_start
        df = pd.DataFrame({"trajectory": sr.own.poses.trajectory, "step": step, "algorithm": ar.key,
                           "warm_start": warm,
                           **{n_: sr.own.poses.points[:, j] for j, n_ in enumerate(sr.own.poses.names)},
                           "median_fitness": np.median(ar.fitness, axis=1),
                           "success_rate": np.mean(ar.fitness < thr, axis=1),
                           "median_evaluations": np.median(ar.evaluations, axis=1)})
        for j, name in enumerate(sr.own.mechanism.pose_names):
            df[f"max_abs_error_{name}"] = ar.errors[:, :, j].max(axis=1)
        frames.append(df)
    return pd.concat(frames, ignore_index=True)


def tracking_timing_table(sr: RunResult) -> pd.DataFrame | None:
    if sr.config.mode != "tracking":
        return None
    runs = sr.config.runs
    return pd.concat([pd.DataFrame({"trajectory": sr.own.poses.trajectory, "step": sr.own.poses.step,
                                    "algorithm": ar.key, "ms_per_run": ar.time_s / runs * 1e3})
                      for ar in _algorithms(sr)], ignore_index=True)


# -- figures -------------------------------------------------------------------------------------
def _name(ar) -> str:
    """The algorithm as the papers name it (cold starts of tracking marked)."""
    name = plotting.algorithm_name(ar.spec.name, ar.spec.params)
    if ar.spec.label and ar.spec.label != ar.spec.name and "cold" in ar.spec.label:
        name += " (cold)"
    return name


#: Line styles of the trajectories of a multi-trajectory tracking study (colour: the algorithm).
_STYLES = ("-", "--", ":", "-.")


def _axis(sr: RunResult, var: str) -> str:
    units = dict(zip(sr.own.mechanism.unknown_names, sr.own.mechanism.unknown_units))
    return f"{var} ({units[var]})" if var in units else var


def ecdf_figure(sr: RunResult, folder: Path, tables: dict) -> list[str]:
    """Fraction of (pose, run) pairs solved vs evaluations (log x), per algorithm."""
    ecdf = tables.get("ecdf.csv")
    if ecdf is None:
        return []
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 4))
    xmax = float(np.nanmax([np.nanmax(ar.evaluations) for ar in _algorithms(sr)] + [1.0]))
    for ar in _algorithms(sr):
        d = ecdf[(ecdf.algorithm == ar.key) & ecdf.evaluations.notna()]
        if d.empty:
            ax.plot([], [], label=f"{_name(ar)} (none solved)")
            continue
        xs = np.concatenate([[d.evaluations.iloc[0]], d.evaluations.to_numpy(), [max(xmax, d.evaluations.max())]])
        ys = np.concatenate([[0.0], d.fraction.to_numpy(), [d.fraction.iloc[-1]]])
        ax.step(xs, ys, where="post", label=_name(ar), lw=1.4)
    ax.set_xscale("log")
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel("function evaluations")
    ax.set_ylabel(f"fraction of (pose, run) pairs with fitness < {sr.config.threshold:g}")
    ax.grid(True, which="major", alpha=0.3)
    plotting.legend_off_data(ax, fontsize=7)
    ax.set_title(f"{sr.config.title or sr.config.name}: {len(sr.own.poses)} poses x {sr.config.runs} runs",
                 fontsize=9)
    names = _save(fig, folder / "ecdf.png")
    plt.close(fig)
    return names


def heatmap_figure(sr: RunResult, folder: Path, tables: dict) -> list[str]:
    """Rows: log10 median final fitness, success rate, median evaluations to the threshold."""
    table = tables.get("heatmap.csv")
    if table is None:
        return []
    plt = _plt()
    a1, a2 = sr.own.poses.grid_axes
    n = len(_algorithms(sr))
    from matplotlib.colors import LogNorm
    fig, axes = plt.subplots(3, n, figsize=(3.0 * n + 1.2, 8.0), squeeze=False, layout="constrained")
    u1, u2 = np.unique(table[a1]), np.unique(table[a2])
    h1 = (u1[1] - u1[0]) / 2 if u1.size > 1 else 0.5
    h2 = (u2[1] - u2[0]) / 2 if u2.size > 1 else 0.5
    ext = [u1[0] - h1, u1[-1] + h1, u2[0] - h2, u2[-1] + h2]
    floor = plotting.floor_of(table["median_fitness"].to_numpy(dtype=float))
    logf = np.log10(np.maximum(table["median_fitness"].to_numpy(dtype=float), floor))
    ev = table["median_evaluations_to_threshold"].to_numpy(dtype=float)
    zero = "\n(exact 0 drawn at the floor " + f"{floor:.0e})" if (table["median_fitness"] <= 0).any() else ""
    rows = [("median_fitness", "log10 median final fitness" + zero, "viridis", (logf.min(), max(logf.max(), logf.min() + 1e-9))),
            ("success_rate", f"success rate (fitness < {sr.config.threshold:g})", "RdYlGn", (0.0, 1.0)),
            ("median_evaluations_to_threshold", "median evaluations to the threshold\n(white: never reached)",
             "magma_r", (np.nanmin(ev) if np.isfinite(ev).any() else 0.0,
                         np.nanmax(ev) if np.isfinite(ev).any() else 1.0))]
    for r, (col, label, cmap, (vmin, vmax)) in enumerate(rows):
        im = None
        for k, ar in enumerate(_algorithms(sr)):
            d = table[table.algorithm == ar.key]
            grid = np.full((u2.size, u1.size), np.nan)
            vals = d[col].to_numpy(dtype=float)
            if col == "median_fitness":
                vals = np.log10(np.maximum(vals, floor))
            grid[np.searchsorted(u2, d[a2]), np.searchsorted(u1, d[a1])] = vals
            ax = axes[r][k]
            if col == "median_evaluations_to_threshold":   # counts differ by decades between methods
                norm = LogNorm(vmin=max(vmin, 1.0), vmax=max(vmax, vmin * 1.01, 1.01))
                im = ax.imshow(grid, origin="lower", extent=ext, aspect="auto", norm=norm, cmap=cmap)
            else:
                im = ax.imshow(grid, origin="lower", extent=ext, aspect="auto", vmin=vmin, vmax=vmax, cmap=cmap)
            ax.grid(False)
            if r == len(rows) - 1:
                ax.set_xlabel(_axis(sr, a1))
            if k == 0:
                ax.set_ylabel(_axis(sr, a2))
            if r == 0:
                ax.set_title(_name(ar), fontsize=9)
        fig.colorbar(im, ax=list(axes[r]), label=label)
    fixed = getattr(sr.config.poses, "fixed", {})
    fig.suptitle(f"{sr.config.title or sr.config.name}" + (f"\n(fixed: {', '.join(f'{k}={v:g}' for k, v in fixed.items())};"
                                                         f" {sr.config.runs} runs per point)" if fixed else ""),
                 fontsize=10)
    names = _save(fig, folder / "heatmap.png")
    plt.close(fig)
    return names


def tracking_figure(sr: RunResult, folder: Path, tables: dict) -> list[str]:
    """Per trajectory step: median final fitness and evaluations (warm-started vs cold)."""
    table = tables.get("tracking.csv")
    if table is None:
        return []
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    floor = plotting.floor_of(table.median_fitness.to_numpy(dtype=float))
    several = table.trajectory.nunique() > 1
    for ar in _algorithms(sr):
        name = _name(ar) + ("" if ar.spec.warm_start or "cold" in ar.key else " (cold)")
        color = None
        for traj, d in table[table.algorithm == ar.key].groupby("trajectory"):
            label = f"{name}, trajectory {traj}" if several else name
            line, = axes[0].plot(d.step, np.maximum(d.median_fitness, floor), marker=".", lw=1, label=label,
                                 color=color, ls=_STYLES[(traj - 1) % len(_STYLES)])
            color = line.get_color()
            axes[1].plot(d.step, d.median_evaluations, marker=".", lw=1, color=color,
                         ls=_STYLES[(traj - 1) % len(_STYLES)])
    axes[0].axhline(sr.config.threshold, color="k", lw=0.8, ls="--")
    axes[0].set_yscale("log")
    axes[0].set_ylabel("final fitness (median over runs)")
    axes[1].set_yscale("log")
    axes[1].set_ylabel("evaluations per step (median)")
    for ax in axes:
        ax.set_xlabel("trajectory step")
        ax.grid(True, alpha=0.3)
    plotting.legend_off_data(axes[-1], source=axes[0], fontsize=7)
    fig.suptitle(f"{sr.config.title or sr.config.name}\n(each step warm-started from the previous "
                 f"step's solution unless marked cold)", fontsize=10)
    fig.tight_layout()
    names = _save(fig, folder / "tracking.png")
    plt.close(fig)
    return names


def tracking_time_figure(sr: RunResult, folder: Path, tables: dict) -> list[str]:
    """Time per step and run (measured; TIMING.md)."""
    table = tables.get("tracking_timing.csv")
    if table is None:
        return []
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 3.6))
    for ar in _algorithms(sr):
        color = None
        for traj, d in table[table.algorithm == ar.key].groupby("trajectory"):
            line, = ax.plot(d.step, d.ms_per_run, marker=".", lw=1, color=color, ls=_STYLES[(traj - 1) % len(_STYLES)],
                            label=None if color is not None else
                            _name(ar) + ("" if ar.spec.warm_start or "cold" in ar.key else " (cold)"))
            color = line.get_color()
    ax.set_yscale("log")
    ax.set_xlabel("trajectory step")
    ax.set_ylabel("time per step and run (ms)")
    ax.grid(True, alpha=0.3)
    plotting.legend_off_data(ax, fontsize=7)
    names = _save(fig, folder / "tracking_time.png")
    plt.close(fig)
    return names


# -- folder --------------------------------------------------------------------------------------
def meta(sr: RunResult) -> dict:
    """What the config and the seed fix (the environment goes to env.json)."""
    objective = sr.config.objective
    if objective is None:
        make = ik_problem if sr.own.mechanism.kind == "serial" else fk_problem
        objective = getattr(make(sr.own.mechanism, sr.own.poses.inputs[0]), "objective", None)
    return {
        "kind": "study", "experiment": sr.config.name, "paper": sr.config.paper, "title": sr.config.title,
        "config_file": sr.source, "config": sr.config.model_dump(mode="json"), "seed": sr.config.seed,
        "task_seeds": "pose (or step) i of algorithm L: fkopt.run.solving.task_seed(seed, i, L); "
                      "run k: child k of that seed (fkopt.numerics.streams)",
        "fingerprint": sr.config.fingerprint(), "poses": len(sr.own.poses),
        "mechanism": sr.own.mechanism.describe(), "objective": objective,
    }
