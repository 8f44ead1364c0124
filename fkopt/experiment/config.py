"""Experiment files: the YAML schema, validated with pydantic.

An experiment file describes one table/figure of a paper (or a study of one's own)::

    name: tab2_tab3_fig2            # folder name of the results
    paper: mao2017                  # SPEC.md key (optional)
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
from typing import Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, PrivateAttr, ValidationError, field_validator, model_validator

from ..errors import FkoptError


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class MechanismSpec(Strict):
    name: str
    geometry: dict[str, Any] = Field(default_factory=dict)
    bounds: dict[str, tuple[float, float]] = Field(default_factory=dict)


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
    random: int = Field(ge=1, description="number of random cases")
    seed: int = 0


class AlgorithmSpec(Strict):
    name: str
    label: str | None = None
    params: dict[str, Any] = Field(default_factory=dict)
    #: Overrides the experiment's population (number of starts for the local methods nr/lm, >= 1).
    population: int | None = Field(None, ge=1)
    iterations: int | None = Field(None, ge=1)
    #: Start point of local methods (nr, lm): {variable: value}.
    start: dict[str, float] | None = None
    #: The paper's printed statistics for this algorithm (mean_fitness, std_fitness, time_ms, ...).
    printed: dict[str, Any] = Field(default_factory=dict)

    @property
    def key(self) -> str:
        return self.label or self.name


def unique_labels(algos):
    """Algorithm entries are told apart by label (or name): they must be unique."""
    keys = [a.key for a in algos]
    dup = {k for k in keys if keys.count(k) > 1}
    if dup:
        raise ValueError(f"algorithm labels must be unique, '{sorted(dup)[0]}' repeats (add 'label:')")
    return algos


class ExperimentConfig(Strict):
    name: str = Field(pattern=r"^[A-Za-z0-9_.-]+$")
    paper: str | None = None
    title: str = ""
    description: str = ""
    mechanism: MechanismSpec
    objective: str | None = None
    cases: list[CaseSpec] | RandomCases
    algorithms: list[AlgorithmSpec] = Field(min_length=1)
    population: int = Field(10, ge=2)
    iterations: int = Field(100, ge=1)
    runs: int = Field(30, ge=1)
    seed: int = 0
    threshold: float | None = Field(None, gt=0)
    stop_at_threshold: bool = False
    batch: bool = True
    snapshots: list[int] = Field(default_factory=list)
    #: Extra figures: variables (best-so-far pose vs iteration), snapshots (population scatter),
    #: extras (algorithm records such as ACO pheromone), cases (per-case error and time).
    figures: list[Literal["variables", "snapshots", "extras", "cases"]] = Field(default_factory=list)
    #: Experiment-level printed values and notes for the report.
    printed: dict[str, Any] = Field(default_factory=dict)
    #: Which regression check reruns it: "ci" (every CI run and `make check`) or "full"
    #: (`make check` only, for experiments too long for CI).
    check: Literal["ci", "full"] = "ci"
    #: Folder of the config file: relative files of the mechanism (URDF) are resolved there.
    _folder: Path | None = PrivateAttr(None)

    @field_validator("algorithms")
    @classmethod
    def _unique_labels(cls, algos):
        return unique_labels(algos)

    @model_validator(mode="after")
    def _stop_needs_threshold(self):
        if self.stop_at_threshold and self.threshold is None:
            raise ValueError("stop_at_threshold needs a threshold")
        return self


def _one_line(err: ValidationError) -> str:
    first = err.errors()[0]
    loc = ".".join(str(p) for p in first["loc"] if not str(p).startswith(("function-", "list[", "RandomCases")))
    msg = first["msg"].removeprefix("Value error, ")
    if first["type"] == "extra_forbidden":
        msg = "unknown field"
    return f"{loc}: {msg}" if loc else msg


def load_config(path: str | Path) -> ExperimentConfig:
    """Read and validate an experiment file; errors name the file, line or field."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as err:
        raise FkoptError(f"{path}: cannot read ({err.strerror})") from None
    try:
        data = yaml.safe_load(text)
    except yaml.MarkedYAMLError as err:
        mark = err.problem_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else "?"
        raise FkoptError(f"{path}: malformed YAML at {where}: {err.problem}") from None
    except yaml.YAMLError as err:
        raise FkoptError(f"{path}: malformed YAML: {err}") from None
    if not isinstance(data, dict):
        raise FkoptError(f"{path}: expected a mapping of experiment fields at the top level")
    try:
        config = ExperimentConfig(**data)
    except ValidationError as err:
        raise FkoptError(f"{path}: {_one_line(err)}") from None
    config._folder = path.parent
    return config
