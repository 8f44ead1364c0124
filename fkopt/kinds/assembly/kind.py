"""Assembly-mode experiments (``kind: assembly``): every real forward solution of one input.

A file names a parallel mechanism (with geometry), the measured joints, the seed and search
settings of :func:`fkopt.kinematics.assembly_modes.all_solutions`, and optionally the known number of real
solutions (``expected``; e.g. 40 for Dietmaier's 6-6 platform). The folder gets

* ``solutions.csv`` -- every solution found inside the bounds, sorted by pose, with its residual
  ``max |ik(pose) - joints|`` (relative to max(1, |joint|)) and how many starts (or homotopy
  paths, for a 6-6 platform on the compiled path) reached it;
* ``summary.csv``   -- the count against ``expected`` and the residual statistics, in the column
  names experiments use (so ``fkopt check`` and the report read it the same way);
* ``timing.csv``    -- wall time of the search (the only non-deterministic file);
* ``meta.json``     -- config, seed, mechanism, digests of the CSVs; ``env.json`` -- versions, platform.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import pandas as pd
from pydantic import Field, ValidationError

from fkopt.errors import FkoptError
from fkopt.files import error_line
from fkopt.run.record import BATCH, timing_record, timing_table as record_timing_table
from fkopt.run.result import RunResult
from fkopt.run.tasks import Kind, Plan, Task
from fkopt.run.config_base import MAX_ITERATIONS, MAX_POPULATION, Located, MechanismSpec, Seed, files_folder
from fkopt.run.kinds import register
from fkopt.run.solving import build_mechanism
from fkopt.run.writers import CURVES, RUNS, TABLE, TIMING, Output
from fkopt.kinematics.assembly_modes import all_solutions, prepare, solutions_to_dict

KIND = "assembly"


class AssemblyConfig(Located):
    kind: Literal["assembly"]
    paper: str = "assembly"
    mechanism: MechanismSpec
    joints: dict[str, float]
    seed: int = Seed()
    #: Starts per round of the multi-start Newton (default: the solver's own, 2000 for 6-SPS).
    population: int | None = Field(None, ge=1, le=MAX_POPULATION)
    #: Newton iterations per start.
    iterations: int = Field(60, ge=1, le=MAX_ITERATIONS)
    runs: Literal[1] = 1
    tol: float = Field(1e-9, gt=0)
    dedup: float = Field(1e-6, gt=0)
    #: ``all_solutions``' method: auto (the certified homotopy for a 6-SPS platform on the compiled
    #: path, else the multi-start Newton), homotopy or restarts.
    method: Literal["auto", "homotopy", "restarts"] = "auto"
    #: Known number of real solutions, for the report.
    expected: int | None = Field(None, ge=0)
    printed: dict[str, Any] = Field(default_factory=dict)
    check: Literal["ci", "full"] = "ci"


def assembly_from_dict(data: dict, where: str) -> AssemblyConfig:
    try:
        return AssemblyConfig(**data)
    except ValidationError as err:
        raise FkoptError(f"{where}: {error_line(err, data=data, model=AssemblyConfig)}") from None


@dataclass
class AssemblyOwn:
    """What only an assembly search has (the :attr:`fkopt.run.result.RunResult.own` slot): its
    mechanism and the solutions it found (one row each: pose, residual, hits) with the search's
    counts."""

    mechanism: object
    solutions: pd.DataFrame         # pose variables, residual, hits; most hits first
    starts: int
    outside: int                    # distinct real solutions found outside the bounds
    round_size: int
    solver_time_s: float            # the search's own account of its time
    method: str = "restarts"        # all_solutions' method that ran: homotopy or restarts


def search(config: AssemblyConfig, source: str | None = None, mech=None) -> dict:
    """The search; its record, JSON-able: every solution found (pose, residual, hits), the
    search's counts and its wall time. ``mech``: the config's mechanism, already built (else
    built here, its relative files beside ``source``)."""
    mech = build_mechanism(config, files_folder(config, source)) if mech is None else mech
    prepare(mech, config.method)          # compiled code and start system loaded outside the timed search
    start = time.perf_counter()
    sols = all_solutions(mech, config.joints, seed=config.seed, round_size=config.population,
                         tol=config.tol, dedup=config.dedup, iterations=config.iterations, method=config.method)
    wall = time.perf_counter() - start
    found = solutions_to_dict(sols)
    return {"solutions": [{**s["pose"], "residual": s["residual"], "hits": s["hits"]} for s in found["solutions"]],
            "starts": found["starts"], "outside": found["outside"], "time_s": found["time_s"],
            "round_size": int(sols.settings["round_size"]), "wall_s": wall, "method": sols.method}


# -- files (listed in OUTPUTS below) -------------------------------------------
def solutions_table(ar: RunResult) -> pd.DataFrame:
    names = list(ar.own.mechanism.pose_names)
    solutions = ar.own.solutions.sort_values(names, kind="stable").reset_index(drop=True)
    solutions.insert(0, "solution", np.arange(1, len(solutions) + 1))
    return solutions


def summary_table(ar: RunResult) -> pd.DataFrame:
    config, own = ar.config, ar.own
    res = own.solutions["residual"].to_numpy(float)
    res = res if len(res) else np.array([np.nan])
    return pd.DataFrame([{
        "case": "given joints", "algorithm": "all_solutions",
        "method": "homotopy" if own.method == "homotopy" else "newton-multistart",
        "population": own.round_size,
        "iterations": config.iterations, "runs": 1,
        "solutions_found": len(own.solutions), "expected": config.expected if config.expected is not None else np.nan,
        "starts": own.starts, "outside_bounds": own.outside,
        "median_fitness": float(np.median(res)), "mean_fitness": float(np.mean(res)),
        "best_fitness": float(np.min(res)), "worst_fitness": float(np.max(res)),
        "mean_evaluations": float(own.starts),
    }])


def timing_table(ar: RunResult) -> pd.DataFrame:
    """The search's wall time, one batch of the timing record (the one timing writer,
    :func:`fkopt.run.record.timing_table`), with the solver's own time and the printed ones."""
    key = ("given joints", "all_solutions")
    settings = {key: {"runs": 1, "total_s": ar.wall_s, "solver_time_s": ar.own.solver_time_s,
                      **{f"printed_{k}": v for k, v in sorted(ar.config.printed.items()) if k.endswith("_s")}}}
    return record_timing_table(ar.timing, settings, names={"solver": "algorithm"})


def meta(ar: RunResult) -> dict:
    config = ar.config
    return {"experiment": config.name, "paper": config.paper, "title": config.title, "kind": KIND,
            "config_file": ar.source, "config": config.model_dump(mode="json"), "seed": config.seed,
            "mechanism": ar.own.mechanism.describe(),
            "objective": f"all real solutions ({'parameter homotopy' if ar.own.method == 'homotopy' else 'multi-start Newton'})"}


# -- the pipeline kind (fkopt.run.pipeline) ------------------------------------------------------
def _validate(config: AssemblyConfig, plan) -> int:
    mech = plan.context                                  # built by the plan
    if mech.kind != "parallel":
        raise FkoptError(f"mechanism '{mech.name}' is {mech.kind}; assembly modes need a parallel mechanism")
    mech.vector(config.joints, mech.joint_names, "joints")
    starts = config.population or 2000
    return starts * len(mech.unknown_names) ** 2 * 8 * 40


def _plan(config: AssemblyConfig, source: str | None, timing: bool = True):
    """One task: the search (timed, so it runs in this process; its time is part of the result)."""
    mech = build_mechanism(config, files_folder(config, source))
    payload = {"config": config.model_dump(mode="json"), "source": source}
    return Plan([Task("search", payload, "all solutions")], solve_task,
                local=lambda _: search(config, source, mech), context=mech, name=config.name)


def solve_task(payload: dict) -> dict:
    """Worker: the search, rebuilt from the payload."""
    return search(assembly_from_dict(payload["config"], "assembly task"), payload["source"])


def _merge(config: AssemblyConfig, plan, ran, *, source: str | None = None, **_) -> RunResult:
    """The search's :class:`~fkopt.run.result.RunResult`: no run record (one search, no runs), its
    wall time as one batch of the timing record, the solutions in ``own`` (:class:`AssemblyOwn`)."""
    mech, rec = plan.context, ran.records["search"]
    solutions = pd.DataFrame(rec["solutions"], columns=[*mech.pose_names, "residual", "hits"])
    timing = timing_record(KIND, {"problem": config.name, "case": "given joints", "solver": "all_solutions",
                                  "runs": 1, "seconds": rec["wall_s"], "mode": BATCH})
    own = AssemblyOwn(mech, solutions, int(rec["starts"]), int(rec["outside"]), int(rec["round_size"]),
                      float(rec["time_s"]), rec.get("method", "restarts"))
    return RunResult(config, None, timing, None, own, rec["wall_s"], source, list(ran.computed))


#: The files of an assembly search's folder, in the order they are written.
OUTPUTS = (
    Output("summary.csv", summary_table, TABLE),
    Output("solutions.csv", solutions_table, CURVES, float_format="%.12g", rows=RUNS),
    Output("timing.csv", timing_table, TIMING),
)

ASSEMBLY = register(Kind(KIND, assembly_from_dict, _plan, _validate, _merge, OUTPUTS, meta, AssemblyConfig))
