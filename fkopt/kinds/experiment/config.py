"""Experiment files: the YAML schema, validated with pydantic.

An experiment file describes one table/figure of a paper (or a study of one's own)::

    name: tab2_tab3_fig2            # folder name of the results
    paper: mao2017                  # docs/models.md key (optional)
    title: "Tab. 2, Tab. 3 and Fig. 2: ACO vs ABC vs GABC"
    mechanism: {name: 3-rps, geometry: {ra: 274, rb: 158}, bounds: {z: [400, 700]}}
    objective: squared              # squared | absolute (parallel); paper | geodesic (serial)
    cases:                          # target poses, measured joints, or both
      - pose: {alpha: 9, beta: 13, z: 622}
    algorithms:
      - name: gabc
        params: {rule: mao2017}
        printed: {mean_fitness: 4.10e-17, time_ms: 361.3}
    population: 10
    iterations: 600
    runs: 30
    seed: 2017
    threshold: 1.0e-10              # success rate / iterations-to-threshold are measured against it
    stop_at_threshold: false        # true: every run stops once below the threshold (Tab. 4/5)

A case gives the measured joints directly (``joints``) or a target ``pose`` whose joints
fkopt computes with its own closed-form map; with both, the given joints are solved and the
pose is the nominal target, and the mismatch between the two is reported (mao2017's printed
leg lengths). ``cases`` may instead be ``{random: N, seed: S}``: N poses uniform in the
bounds (parallel mechanisms) or the poses of N uniform random joint vectors (serial arms,
hence reachable).
"""
from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import Field, ValidationError, field_validator, model_validator

from fkopt.errors import FkoptError
from fkopt.files import error_line, load_mapping
from fkopt.run.config_base import MAX_CASES, RunConfig, Seed, Strict

class CaseSpec(Strict):
    label: str | None = None
    pose: dict[str, float] | None = None
    joints: dict[str, float] | None = None
    #: Another pose to compare the solution with, e.g. the exact solution of printed joints.
    reference: dict[str, float] | None = None
    reference_label: str = "reference"
    #: Printed values of this case: {algorithm label: {variable: value}} (paper's table).
    printed: dict[str, dict[str, float]] = Field(default_factory=dict)

    @model_validator(mode="after")
    def _needs_input(self):
        if self.pose is None and self.joints is None:
            raise ValueError("a case needs 'pose' or 'joints' (or both)")
        return self


class RandomCases(Strict):
    random: int = Field(ge=1, le=MAX_CASES, description="number of random cases")
    seed: int = Seed()


class ExperimentConfig(RunConfig):
    """A :class:`RunConfig` whose targets are listed (or drawn at random) as cases."""

    cases: list[CaseSpec] | RandomCases
    batch: bool = True
    snapshots: list[int] = Field(default_factory=list)
    #: Extra figures: variables (best-so-far pose vs iteration), snapshots (population scatter),
    #: extras (algorithm records such as ACO pheromone), cases (per-case error and time), time
    #: (time of each timed run).
    figures: list[Literal["variables", "snapshots", "extras", "cases", "time"]] = Field(default_factory=list)

    @field_validator("cases", mode="before")
    @classmethod
    def _one_form(cls, cases):
        # the two forms do not mix: a list holds listed cases only
        if isinstance(cases, list):
            for i, item in enumerate(cases):
                if isinstance(item, dict) and "random" in item:
                    raise ValueError(f"item {i} is {{random: ...}}: cases is either a list of cases (each with "
                                     "pose and/or joints) or one mapping {random: N, seed: S} for N poses "
                                     "uniform in the bounds, not both; put the random cases in a config of "
                                     "their own")
        return cases

    @field_validator("cases")
    @classmethod
    def _some_cases(cls, cases):
        if isinstance(cases, list) and not 1 <= len(cases) <= MAX_CASES:
            raise ValueError(f"needs 1 to {MAX_CASES} cases, got {len(cases)}")
        return cases


#: ``cases`` is a list of cases or ``{random: N}``: report the error of the form the user wrote.
CASE_BRANCHES = {"cases": {"random": "RandomCases"}}


def _one_line(err: ValidationError, data: dict | None = None) -> str:
    return error_line(err, CASE_BRANCHES, data, model=ExperimentConfig)


def experiment_from_dict(data: dict, where: str) -> ExperimentConfig:
    try:
        return ExperimentConfig(**data)
    except ValidationError as err:
        raise FkoptError(f"{where}: {_one_line(err, data)}") from None


def load_config(path: str | Path) -> ExperimentConfig:
    """Read and validate an experiment file; errors name the file, line or field."""
    data = load_mapping(path, "experiment fields")
    config = experiment_from_dict(data, str(path))
    config._folder = Path(path).parent   # relative files (e.g. a URDF) resolve beside the config
    return config
