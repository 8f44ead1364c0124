"""The config models every kind shares (floor 3, the engine): documented upper limits, seeds,
strict models, the results folder's names (:class:`Located`), a mechanism and an algorithm entry,
:class:`RunConfig` (what every config that runs algorithms x targets x runs shares), which fields
change the numbers (:func:`numeric_fields`) and where a config's relative files resolve
(:func:`files_folder`). The kinds' own models (:mod:`fkopt.kinds.experiment.config`,
:mod:`fkopt.kinds.study.config`, :mod:`fkopt.kinbench.config`) build on these."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, PrivateAttr, field_validator, model_validator

from fkopt.errors import FkoptError
from fkopt.files import MAX_COMPONENT, check_component, no_quoted_numbers

#: Documented upper limits (docs/cli.md, "Bad input"); a memory estimate refuses smaller jobs that
#: still cannot fit (:func:`fkopt.run.memory.check_memory`).
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


def files_folder(config, source: str | Path | None = None) -> Path | None:
    """Where ``config``'s relative files (a URDF's ``geometry.file``, a suite's pose sets and
    outside logs) resolve: the folder of the file it was read from (set once, by its loader),
    else the folder of ``source``, else None (the working directory). A run passes the answer
    down; nothing sets it on the config afterwards."""
    folder = getattr(config, "_folder", None)
    return Path(folder) if folder is not None else (Path(source).parent if source else None)
