"""Assembly-mode experiments (``kind: assembly``): every real forward solution of one input.

A file names a parallel mechanism (with geometry), the measured joints, the seed and search
settings of :func:`fkopt.kinematics.assembly_modes.all_solutions`, and optionally the known number of real
solutions (``expected``; e.g. 40 for Dietmaier's 6-6 platform). The folder gets

* ``solutions.csv`` -- every solution found inside the bounds, sorted by pose, with its residual
  ``max |ik(pose) - joints|`` (relative to max(1, |joint|)) and how many starts reached it;
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
from fkopt.run.tasks import Kind, Plan, Task
from fkopt.run.config_base import MAX_ITERATIONS, MAX_POPULATION, Located, MechanismSpec, Seed, files_folder
from fkopt.run.kinds import register
from fkopt.run.solving import build_mechanism
from fkopt.run.writers import CURVES, RUNS, TABLE, TIMING, Output

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
class AssemblyResult:
    config: AssemblyConfig
    mechanism: object
    solutions: Any                  # fkopt.kinematics.assembly_modes.Solutions
    wall_s: float
    source: str | None = None


def run_assembly(config: AssemblyConfig, source: str | None = None, mech=None) -> AssemblyResult:
    """The search; ``mech``: the config's mechanism, already built (else built here, its
    relative files beside ``source``)."""
    from fkopt.kinematics.assembly_modes import all_solutions
    mech = build_mechanism(config, files_folder(config, source)) if mech is None else mech
    start = time.perf_counter()
    sols = all_solutions(mech, config.joints, seed=config.seed, round_size=config.population,
                         tol=config.tol, dedup=config.dedup, iterations=config.iterations)
    return AssemblyResult(config, mech, sols, time.perf_counter() - start, source)


# -- files (listed in OUTPUTS below) -------------------------------------------
def solutions_table(ar: AssemblyResult) -> pd.DataFrame:
    rows = [{**{n: float(v) for n, v in s.pose.items()}, "residual": float(s.residual), "hits": int(s.hits)}
            for s in ar.solutions]
    solutions = pd.DataFrame(rows, columns=[*ar.mechanism.pose_names, "residual", "hits"])
    solutions = solutions.sort_values(list(ar.mechanism.pose_names), kind="stable").reset_index(drop=True)
    solutions.insert(0, "solution", np.arange(1, len(solutions) + 1))
    return solutions


def summary_table(ar: AssemblyResult) -> pd.DataFrame:
    config, sols = ar.config, ar.solutions
    res = solutions_table(ar)["residual"].to_numpy()
    res = res if len(res) else np.array([np.nan])
    return pd.DataFrame([{
        "case": "given joints", "algorithm": "all_solutions", "method": "newton-multistart",
        "population": int(sols.settings["round_size"]),
        "iterations": config.iterations, "runs": 1,
        "solutions_found": len(sols), "expected": config.expected if config.expected is not None else np.nan,
        "starts": int(sols.starts), "outside_bounds": int(getattr(sols, "outside", 0)),
        "median_fitness": float(np.median(res)), "mean_fitness": float(np.mean(res)),
        "best_fitness": float(np.min(res)), "worst_fitness": float(np.max(res)),
        "mean_evaluations": float(sols.starts),
    }])


def timing_table(ar: AssemblyResult) -> pd.DataFrame:
    """The search's wall time, one batch of the timing record (the one timing writer,
    :func:`fkopt.run.record.timing_table`), with the solver's own time and the printed ones."""
    key = ("given joints", "all_solutions")
    timing = timing_record(KIND, {"problem": ar.config.name, "case": key[0], "solver": key[1], "runs": 1,
                                  "seconds": ar.wall_s, "mode": BATCH})
    settings = {key: {"runs": 1, "total_s": ar.wall_s, "solver_time_s": float(ar.solutions.time_s),
                      **{f"printed_{k}": v for k, v in sorted(ar.config.printed.items()) if k.endswith("_s")}}}
    return record_timing_table(timing, settings, names={"solver": "algorithm"})


def meta(ar: AssemblyResult) -> dict:
    config = ar.config
    return {"experiment": config.name, "paper": config.paper, "title": config.title, "kind": KIND,
            "config_file": ar.source, "config": config.model_dump(mode="json"), "seed": config.seed,
            "mechanism": ar.mechanism.describe(), "objective": "all real solutions (multi-start Newton)"}


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
                local=lambda _: run_assembly(config, source, mech), context=mech, name=config.name)


def solve_task(payload: dict) -> AssemblyResult:
    """Worker: the search, rebuilt from the payload."""
    return run_assembly(assembly_from_dict(payload["config"], "assembly task"), payload["source"])


def _merge(config: AssemblyConfig, plan, ran, **_) -> AssemblyResult:
    return ran.records["search"]


#: The files of an assembly search's folder, in the order they are written.
OUTPUTS = (
    Output("summary.csv", summary_table, TABLE),
    Output("solutions.csv", solutions_table, CURVES, float_format="%.12g", rows=RUNS),
    Output("timing.csv", timing_table, TIMING),
)

ASSEMBLY = register(Kind(KIND, assembly_from_dict, _plan, _validate, _merge, OUTPUTS, meta, AssemblyConfig))
