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
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, PrivateAttr, ValidationError, field_validator, model_validator

from ..errors import FkoptError
from ..files import MAX_COMPONENT, check_component, error_line, load_mapping, no_quoted_numbers

#: Documented upper limits (docs/cli.md, "Bad input"); a memory estimate refuses smaller jobs that
#: still cannot fit (:func:`fkopt.experiment.kinds.check_memory`).
MAX_RUNS = 100_000
MAX_POPULATION = 100_000
MAX_ITERATIONS = 1_000_000
MAX_CASES = 100_000
#: Seeds are non-negative integers below 2**63 (numpy SeedSequence entropy).
MAX_SEED = 2**63 - 1


def Seed(default: int = 0):
    return Field(default, ge=0, le=MAX_SEED)


class Strict(BaseModel):
    #: Unknown fields are errors; NaN and inf are never accepted as numbers, nor text as a number.
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    _numbers = field_validator("*", mode="before")(no_quoted_numbers)


def safe_component(value, field: str):
    """pydantic-side check of ``paper``/``name`` (see :func:`fkopt.files.check_component`)."""
    if value is None:
        return value
    try:
        return check_component(value, field)
    except FkoptError as err:
        raise ValueError(str(err).split(": ", 1)[1]) from None


class Located(Strict):
    """A config that writes ``OUT/<paper>/<name>/``: both are single safe folder names."""

    name: str
    paper: str | None = None
    title: str = ""
    description: str = ""

    @field_validator("name", "paper")
    @classmethod
    def _component(cls, value, info):
        return safe_component(value, info.field_name)

    @property
    def folder_parts(self) -> tuple[str, str]:
        """``(paper, name)``: the results folder is ``OUT/<paper>/<name>/``."""
        return (self.paper or "experiments", self.name)


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
    random: int = Field(ge=1, le=MAX_CASES, description="number of random cases")
    seed: int = Seed()


class AlgorithmSpec(Strict):
    name: str
    #: Tells entries apart (names task files of a study, so it is bounded).
    label: str | None = Field(None, min_length=1, max_length=MAX_COMPONENT)
    params: dict[str, Any] = Field(default_factory=dict)
    #: Overrides the experiment's population (number of starts for the local methods nr/lm, >= 1).
    population: int | None = Field(None, ge=1, le=MAX_POPULATION)
    iterations: int | None = Field(None, ge=1, le=MAX_ITERATIONS)
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


class RunConfig(Located):
    """What every config that runs algorithms x targets x runs shares (experiments, studies):
    names, mechanism, objective, algorithms, budget, seed, threshold, printed values."""

    mechanism: MechanismSpec
    objective: str | None = None
    algorithms: list[AlgorithmSpec] = Field(min_length=1)
    population: int = Field(10, ge=2, le=MAX_POPULATION)
    iterations: int = Field(100, ge=1, le=MAX_ITERATIONS)
    runs: int = Field(30, ge=1, le=MAX_RUNS)
    seed: int = Seed()
    threshold: float | None = Field(None, gt=0)
    stop_at_threshold: bool = False
    #: File stems of the figures, named after the paper figure they mirror, by fkopt's figure kind
    #: (convergence, variables, snapshot_<t>, extras, cases, cases_time, cases_position_error,
    #: position_error, time), e.g. {convergence: fig2}; kinds not named keep the kind as stem.
    figure_names: dict[str, str] = Field(default_factory=dict)
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


#: Fields that never change the numbers: a stored result made from a config differing only
#: in these may be replaced without ``--force`` (and a resumed study may differ in them).
NOT_NUMERIC = ("title", "description", "printed", "check")


def numeric_fields(config: dict) -> dict:
    """The result-changing part of a config mapping (``model_dump(mode="json")``)."""
    data = {k: v for k, v in config.items() if k not in NOT_NUMERIC}
    for key in ("algorithms", "cases"):
        if isinstance(data.get(key), list):
            data[key] = [{k: v for k, v in a.items() if k != "printed"} if isinstance(a, dict) else a
                         for a in data[key]]
    return data



#: ``cases`` is a list of cases or ``{random: N}``: report the error of the form the user wrote.
CASE_BRANCHES = {"cases": {"random": "RandomCases"}}


def _one_line(err: ValidationError, data: dict | None = None) -> str:
    return error_line(err, CASE_BRANCHES, data, model=ExperimentConfig)


def experiment_from_dict(data: dict, where: str) -> ExperimentConfig:
    try:
        return ExperimentConfig(**data)
    except ValidationError as err:
        raise FkoptError(f"{where}: {_one_line(err, data)}") from None


def files_folder(config, source: str | Path | None = None) -> Path | None:
    """Where ``config``'s relative files (a URDF's ``geometry.file``, a suite's pose sets and
    outside logs) resolve: the folder of the file it was read from (set once, by its loader),
    else the folder of ``source``, else None (the working directory). A run passes the answer
    down; nothing sets it on the config afterwards."""
    folder = getattr(config, "_folder", None)
    return Path(folder) if folder is not None else (Path(source).parent if source else None)


def load_config(path: str | Path) -> ExperimentConfig:
    """Read and validate an experiment file; errors name the file, line or field."""
    data = load_mapping(path, "experiment fields")
    config = experiment_from_dict(data, str(path))
    config._folder = Path(path).parent   # relative files (e.g. a URDF) resolve beside the config
    return config
