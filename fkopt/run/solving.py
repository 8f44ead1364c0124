"""One solve path for every kind (floor 3, the engine): a config's mechanism built and checked
(:func:`build_mechanism`), the problem of a case axis (:func:`make_problem`), an algorithm's start
and budget, the per-task seed (:func:`task_seed`) and :func:`solve_cases`, the one
:func:`fkopt.solve` call of experiments' cases, studies' pose chunks and suites' poses.

Seeds: the (case, algorithm) task with case index c and algorithm label L gets the integer
seed ``SeedSequence([seed, c, crc32(L)]).generate_state(1)[0]`` and its run k the k-th child
stream of that (see :mod:`fkopt.numerics.streams`)."""
from __future__ import annotations

import zlib
from pathlib import Path

import numpy as np

from fkopt import registry
from fkopt.errors import FkoptError
from fkopt.mechanisms.base import check_bounds
from fkopt.numerics.rotations import wrap_degrees
from fkopt.problems import fk_problem, ik_problem
from fkopt.run.config_base import AlgorithmSpec, RunConfig, files_folder
from fkopt.solve import Result, contained, make_algorithm, plugin_of, solve


def task_seed(seed: int, case_index: int, label: str) -> int:
    state = np.random.SeedSequence([int(seed), int(case_index), zlib.crc32(label.encode())]).generate_state(1)
    return int(state[0])


def build_mechanism(config: RunConfig, folder: Path | None = None):
    """The config's mechanism, checked before any work: its bounds finite with a finite width
    (:func:`fkopt.mechanisms.base.check_bounds`), and its closed form giving finite values of
    the right shape at the centre of the bounds. A plug-in mechanism that raises or returns
    something else is one line naming it. Relative files resolve in ``folder`` (default:
    :func:`~fkopt.kinds.experiment.config.files_folder`)."""
    cls = registry.mechanism_class(config.mechanism.name)
    who = f"mechanism plug-in '{config.mechanism.name}' ({plugin_of(cls)})" if plugin_of(cls) else None
    geometry = registry.resolve_files(cls, config.mechanism.geometry,
                                      folder if folder is not None else files_folder(config))
    mech = contained(who, lambda: cls(bounds=dict(config.mechanism.bounds), **geometry))
    name = who or config.mechanism.name
    names = contained(who, lambda: tuple(mech.unknown_names))
    check_bounds(name, names, contained(who, lambda: mech.bounds))
    centre = mech.bounds.mean(axis=1)
    closed, out_names = (mech.fk, mech.pose_names) if mech.kind == "serial" else (mech.ik, mech.joint_names)
    try:
        value = np.asarray(contained(who, lambda: closed(centre)), dtype=float)
    except (TypeError, ValueError):
        raise FkoptError(f"{name}: its closed form returned something that is not numbers") from None
    if value.shape != (len(out_names),):
        raise FkoptError(f"{name}: its closed form returned shape {value.shape} at the centre of the bounds, "
                         f"expected ({len(out_names)},) ({', '.join(out_names)})")
    if np.isnan(value).all():
        raise FkoptError(f"{name}: its closed form gives only NaN at the centre of the bounds "
                         f"{centre.round(6).tolist()}; check the geometry")
    return mech


def _check_in_bounds(mech, pose: np.ndarray, where: str) -> None:
    lo, hi = mech.bounds[:, 0], mech.bounds[:, 1]
    for name, v, a, b in zip(mech.unknown_names, pose, lo, hi):
        if not a - 1e-9 <= v <= b + 1e-9:
            raise FkoptError(f"{where}: {name}={v:g} is outside the workspace bounds [{a:g}, {b:g}] "
                             f"(widen mechanism.bounds.{name} or move the pose)")


def make_problem(config: RunConfig, mech, inputs: np.ndarray):
    """The problem of ``inputs`` -- one target ``(m,)`` or a case axis ``(cases, m)`` -- with the
    config's objective: :func:`fkopt.fk_problem` for a parallel mechanism, :func:`fkopt.ik_problem`
    for a serial arm. The one place experiments, studies and tracking steps get a problem from."""
    kwargs = {"objective": config.objective} if config.objective else {}
    if mech.kind == "serial":
        return ik_problem(mech, inputs, **kwargs)
    return fk_problem(mech, inputs, **kwargs)


def outputs_of(mech, x: np.ndarray) -> np.ndarray:
    """What a solution is compared in: the pose itself (parallel) or fk(joints) (serial)."""
    return mech.fk(x) if mech.kind == "serial" else x


def pose_error(mech, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a - b| per pose variable, angle differences wrapped to [-180, 180)."""
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    angle = mech.angle_mask(mech.pose_units)
    return np.abs(np.where(angle, wrap_degrees(d), d))


def start_point(spec: AlgorithmSpec, mech) -> np.ndarray | None:
    """An algorithm's ``start`` as a vector of the unknowns (checked inside the bounds): a pose
    mapping, or (study files) ``"centre"`` -- the centre of the bounds; None: no start."""
    if spec.start is None:
        return None
    if isinstance(spec.start, str):      # "centre" (the schema admits nothing else)
        return mech.bounds.mean(axis=1)
    x0 = mech.vector(spec.start, mech.unknown_names, f"algorithms[{spec.key}].start")
    _check_in_bounds(mech, x0, f"algorithms[{spec.key}].start")
    return x0


def budget(config: RunConfig, spec: AlgorithmSpec) -> dict:
    """The solve settings an algorithm gets from its spec and the config (spec first)."""
    return dict(population=spec.population or config.population,
                iterations=spec.iterations or config.iterations, runs=config.runs,
                target=config.threshold, stop_at_target=config.stop_at_threshold)


def solve_cases(config: RunConfig, spec: AlgorithmSpec, problem, seeds, *, x0=None, **options) -> Result:
    """One algorithm on every case of ``problem`` for ``config.runs`` runs each, in one
    :func:`fkopt.solve` call (cases x runs rows), case c seeded with ``seeds[c]`` (one int for a
    single-target problem). The one solve path of experiments, study chunks and tracking steps;
    ``options`` go to :func:`fkopt.solve` (``batch``, ``snapshots``, ``x_history``, ``runs``)."""
    settings = {**budget(config, spec), **options}
    return solve(problem, make_algorithm(spec.name, spec.params), seed=seeds, x0=x0, **settings)
