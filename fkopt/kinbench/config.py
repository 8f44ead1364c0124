"""Suite files (``kind: suite``): problems x frozen pose sets x solvers x runs at fixed budgets.

::

    kind: suite
    name: kinbench
    paper: kinbench                 # results folder OUT/kinbench/kinbench/
    pose_sets: kinbench-v1          # folder beside this file: manifest.json + one CSV per (problem, set)
    problems:
      - name: mao2017-3rps          # also the pose-set folder of this problem
        problem_class: parallel-fk-3dof   # ranked together with the other problems of its class
        mechanism: {name: 3-rps, geometry: {ra: 274, rb: 158}}
    sets: [uniform, near-singular, boundary, printed]
    poses: 10                       # the first N poses of every set (all when omitted)
    solvers:
      - {name: gabc}                # track from fkopt's table (black-box / jacobian / exact)
      - {name: "mypkg.de:DE", track: black-box}   # plug-ins must name their track
    budget_per_dim: 2000            # evaluation budget of a run = budget_per_dim x dimension
    population: 20                  # swarm size (starts of a local method)
    runs: 5
    seed: 2026
    targets: [1.0e-2, 1.0e-4, 1.0e-6, 1.0e-8, 1.0e-10]
    quick: {problems: [...], solvers: [...], poses: 3, runs: 2, budget_per_dim: 300, queries: 5}
    tracks:                         # kinbench v3: IK solvers on the clock (fkopt.kinbench.clock)
      clock:
        problems: [ur5, panda]      # the suite's URDF arms; queries: their frozen poses of `set`
        solvers: [fkopt.inverse, tracik, rtb-ik_NR, pin-clik, ikpy]   # fkopt.adapters.field names
        reference: rtb-ik_LM        # every time is a ratio to this solver's, query by query
        timeouts_ms: [1, 5, 20]
        set: uniform
        queries: 50                 # the set's first N poses (all when omitted)
        rung: 2                     # the ladder rung (0..3) the time to an answer is judged at
      throughput: {batches: [1, 10, 100, 1000], repeats: 3}   # the clock's arms and batch solvers

A solver's iterations are chosen so its swarm can spend the budget
(``ceil(budget / population)``); every measure is taken at the budget, from the cumulative
evaluation counts each run records, so a solver that spends more per iteration gains nothing.
"""
from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import ConfigDict, Field, PrivateAttr, ValidationError, field_validator, model_validator

from fkopt.errors import FkoptError
from fkopt.registry import ALL_SOLUTIONS_SOLVERS, IK_SOLVERS, PATH_SOLVERS, track_of
from fkopt.run.config_base import MAX_RUNS, AlgorithmSpec, Located, MechanismSpec, Seed, Strict, unique_labels
from fkopt.files import error_line, load_mapping
from fkopt.kinbench import instances     # instances.expand read at call time: tests stand in for it
from fkopt.kinbench.instances import MAX_SUITE_INSTANCES

#: Pose sets of kinbench v1 (see :mod:`fkopt.kinbench.posesets`).
SETS = ("uniform", "near-singular", "boundary", "printed")
#: Tracks ranked separately: fitness only, Jacobian-using, exact/analytic.
TRACKS = ("black-box", "jacobian", "exact")
#: The COCO-style target ladder on the problem's fitness.
TARGETS = (1e-2, 1e-4, 1e-6, 1e-8, 1e-10)
#: Track of fkopt's built-in solvers and the adapters (anything else must state its track).
MAX_BUDGET_PER_DIM = 10_000_000


#: Longest name of a suite with a ``quick:`` block: ``<name>-quick`` (its --quick result) stays a
#: folder name of at most 64 characters, never cut back to the full result's name.
MAX_QUICK_NAME = 64 - len("-quick")


def default_track(name: str) -> str | None:
    """The track of a built-in solver or an adapter (the registry's entry); None for a plug-in."""
    return track_of(name)


class SuiteSolver(AlgorithmSpec):
    track: Literal["black-box", "jacobian", "exact"] | None = None

    @model_validator(mode="after")
    def _track(self):
        if self.track is None:
            self.track = default_track(self.name)
            if self.track is None:
                raise ValueError(f"solver '{self.name}' needs 'track' (allowed: {', '.join(TRACKS)}); "
                                 "fkopt knows the track of its own solvers and adapters only")
        return self


class OutsideSolver(Strict):
    """Results of a solver run outside fkopt (:mod:`fkopt.kinbench.outside`): a CSV ``file`` or
    an IOHprofiler folder ``ioh`` (with the ``algorithm`` to take when it holds several)."""

    solver: str = Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_.+:-]{0,63}$")
    track: Literal["black-box", "jacobian", "exact"]
    file: str | None = Field(None, min_length=1)
    ioh: str | None = Field(None, min_length=1)
    algorithm: str | None = None
    description: str = ""

    @model_validator(mode="after")
    def _one_source(self):
        if (self.file is None) == (self.ioh is None):
            raise ValueError("give exactly one of 'file' (CSV) and 'ioh' (IOHprofiler folder)")
        if self.algorithm is not None and self.ioh is None:
            raise ValueError("'algorithm' selects a solver of an 'ioh' folder; a CSV file holds one")
        return self


class SuiteProblem(Strict):
    #: ``name-ik`` is instance k of a problem with ``instances`` (:mod:`fkopt.kinbench.instances`).
    name: str = Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_.+-]{0,63}$")
    #: Problems of one class are ranked together (no alias such as ``class``: a stored config
    #: must dump to the same mapping it was read from).
    problem_class: str = Field(min_length=1, max_length=64)
    mechanism: MechanismSpec
    objective: str | None = None
    #: K seeded geometries of a parallel mechanism: the problem stands for name-i1 ... name-iK.
    instances: int | None = Field(None, ge=1, le=100)


class SolverSubset(Strict):
    """Cells a group of solvers runs instead of the whole suite: the expensive per-point solvers
    (swarms, hybrids, DE) on fewer problems, poses and runs, while the others run everything.
    Omitted fields keep the suite's value; a subset only cuts (``poses`` <= the suite's,
    ``runs`` <= the suite's). Every board of the results compares solvers on the cells they all
    ran (:func:`fkopt.kinbench.measures.boards`): one board for the whole suite (its solvers
    without a subset) and one per subset (every solver that ran all of its cells)."""

    name: str = Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_.+-]{0,31}$")
    solvers: list[str] = Field(min_length=1)
    problems: list[str] | None = Field(None, min_length=1)
    sets: list[Literal["uniform", "near-singular", "boundary", "printed"]] | None = Field(None, min_length=1)
    poses: int | None = Field(None, ge=1)
    runs: int | None = Field(None, ge=1, le=MAX_RUNS)
    description: str = ""


#: The board of the suite's own cells (its solvers without a subset); no subset may take the name.
FULL_BOARD = "full"


class QuickTier(Strict):
    """The subset ``--quick`` runs (and ``fkopt check`` reruns): fewer problems, solvers, poses,
    runs and a smaller budget. Omitted fields keep the full suite's value."""

    problems: list[str] | None = None
    solvers: list[str] | None = None
    sets: list[Literal["uniform", "near-singular", "boundary", "printed"]] | None = None
    poses: int | None = Field(None, ge=1)
    runs: int | None = Field(None, ge=1, le=MAX_RUNS)
    budget_per_dim: int | None = Field(None, ge=1, le=MAX_BUDGET_PER_DIM)
    #: queries per arm of the clock track (its arms: those of tracks.clock.problems kept here) and of
    #: the all-solutions track
    queries: int | None = Field(None, ge=1)
    #: paths per arm of the paths track
    paths: int | None = Field(None, ge=1)


#: Solvers the clock track knows: the organiser's and the field's (the registry's IK solvers).
def clock_solvers() -> tuple[str, ...]:
    return IK_SOLVERS


class ClockSubmission(Strict):
    """A solver run elsewhere on the clock track (:mod:`fkopt.kinbench.submissions`): a CSV of
    its answers and wall times per query, the machine, and the reference timed beside it."""

    solver: str = Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_.+:-]{0,63}$")
    file: str = Field(min_length=1)
    machine: str = Field(min_length=1, max_length=200)
    reference: str | None = None
    description: str = ""


class ClockTrack(Strict):
    """The clock track (:mod:`fkopt.kinbench.clock`): IK of the suite's URDF arms, every solver
    at every timeout, times as ratios to ``reference`` measured in the same job."""

    problems: list[str] = Field(min_length=1)
    solvers: list[str] = Field(min_length=1)
    reference: str = "rtb-ik_LM"
    timeouts_ms: list[float] = Field(default_factory=lambda: [1.0, 5.0, 20.0], min_length=1)
    set: Literal["uniform", "near-singular", "boundary", "printed"] = "uniform"
    queries: int | None = Field(None, ge=1, le=100_000)
    rung: int = Field(2, ge=0, le=3)
    submissions: list[ClockSubmission] = Field(default_factory=list)
    #: FK of the suite's 6-DOF parallel mechanisms among ``problems``: solvers, reference, timeouts
    fk_solvers: list[str] = Field(default_factory=lambda: ["fkopt.forward"], min_length=1)
    fk_reference: str = "scipy-least_squares"
    fk_timeouts_ms: list[float] = Field(default_factory=lambda: [20.0, 100.0, 500.0], min_length=1)

    @model_validator(mode="after")
    def _names(self):
        known = clock_solvers()
        for name in [*self.solvers, self.reference]:
            if name not in known:
                raise ValueError(f"solver '{name}' is not a clock-track solver (allowed: {', '.join(known)})")
        for field in ("problems", "solvers", "fk_solvers"):      # each list alike: a repeat is refused
            values = getattr(self, field)
            if len(set(values)) != len(values):
                raise ValueError(f"{field}: '{next(v for v in values if values.count(v) > 1)}' repeats; "
                                 "problems, solvers and fk_solvers must not repeat")
        for field in ("timeouts_ms", "fk_timeouts_ms"):
            ts = getattr(self, field)
            if any(t <= 0 or t > 10_000 for t in ts) or sorted(set(ts)) != ts:
                raise ValueError(f"{field}: distinct, increasing, in (0, 10000] ms")
        fk_known = ("fkopt.forward", "scipy-least_squares")
        for name in [*self.fk_solvers, self.fk_reference]:
            if name not in fk_known:
                raise ValueError(f"fk solver '{name}' is not a clock-track FK solver (allowed: {', '.join(fk_known)})")
        for sub in self.submissions:
            if sub.solver in [*self.solvers, self.reference, *self.fk_solvers, self.fk_reference] or [s.solver for s in self.submissions].count(sub.solver) > 1:
                raise ValueError(f"submissions: solver '{sub.solver}' repeats a solver of the track")
            if sub.reference is not None and sub.reference not in (self.reference, self.fk_reference):
                raise ValueError(f"submissions[{sub.solver}].reference: '{sub.reference}' is not the track's "
                                 f"reference ({self.reference} for IK, {self.fk_reference} for FK); its times "
                                 "would not be ratios to the same solver")
        return self


class ThroughputTrack(Strict):
    """Queries per second at each batch size, for the clock's solvers that take batches."""

    batches: list[int] = Field(default_factory=lambda: [1, 10, 100, 1000], min_length=1)
    #: batch sizes for FK of parallel mechanisms (fkopt.forward: ~0.1 s per pose on Dietmaier's platform)
    fk_batches: list[int] = Field(default_factory=lambda: [1, 10, 100], min_length=1)
    repeats: int = Field(3, ge=1, le=100)
    #: IK solvers on this track only, besides the clock's batch-taking ones: batched packages whose
    #: per-query call is not how their authors use them (pytorch-kinematics)
    solvers: list[str] = Field(default_factory=list)

    @field_validator("solvers")
    @classmethod
    def _solvers(cls, solvers):
        known = clock_solvers()
        for name in solvers:
            if name not in known:
                raise ValueError(f"solver '{name}' is not a clock-track solver (allowed: {', '.join(known)})")
        if len(set(solvers)) != len(solvers):
            raise ValueError("solvers must not repeat")
        return solvers

    @field_validator("batches", "fk_batches")
    @classmethod
    def _batches(cls, batches):
        if any(b < 1 or b > 100_000 for b in batches) or sorted(set(batches)) != batches:
            raise ValueError("batches: distinct, increasing, 1 to 100000")
        return batches


def _entries(names: list[str], known: tuple[str, ...], track: str) -> list[str]:
    for name in names:
        if name not in known:
            raise ValueError(f"solver '{name}' is not an entry of the {track} track (allowed: {', '.join(known)})")
    if len(set(names)) != len(names):
        raise ValueError(f"solvers: '{next(v for v in names if names.count(v) > 1)}' repeats")
    return names


class SolutionsTrack(Strict):
    """Every IK solution of a pose (:mod:`fkopt.kinbench.solution_sets`): recall against the
    analytic sets and against the union of every entry's verified answers, time per pose as a
    ratio to the reference's."""

    problems: list[str] = Field(min_length=1)
    solvers: list[str] = Field(min_length=1)
    #: times are ratios to this entry's, pose by pose; its median time per pose on an arm is the
    #: budget of the entries that restart until a time has passed
    reference: str = "fkopt.inverse-all"
    #: the entry whose sets are the analytic reference of recall ("not applicable" where it cannot take the arm)
    analytic: str = "eaik-all"
    #: problem -> the joint locked in every entry (at LOCK_SHARE of its range): a 7-joint arm's finite sets
    locked: dict[str, str] = Field(default_factory=dict)
    set: Literal["uniform", "near-singular", "boundary", "printed"] = "uniform"
    queries: int | None = Field(None, ge=1, le=10_000)

    @field_validator("solvers")
    @classmethod
    def _solvers(cls, solvers):
        return _entries(solvers, ALL_SOLUTIONS_SOLVERS, "all-solutions")

    @model_validator(mode="after")
    def _known(self):
        for field in ("reference", "analytic"):
            if getattr(self, field) not in self.solvers:
                raise ValueError(f"{field}: '{getattr(self, field)}' is not one of the track's solvers "
                                 f"({', '.join(self.solvers)})")
        for problem in self.locked:
            if problem not in self.problems:
                raise ValueError(f"locked: '{problem}' is not one of the track's problems ({', '.join(self.problems)})")
        return self


class PathsTrack(Strict):
    """IK along frozen paths (:mod:`fkopt.kinbench.paths`): success (every waypoint within the
    tolerance, no joint step above the bound) and time per waypoint as a ratio to the reference's."""

    problems: list[str] = Field(min_length=1)
    solvers: list[str] = Field(min_length=1)
    reference: str = "fkopt.inverse_path"
    #: the frozen path set: a folder beside the suite file (manifest.json + one CSV per problem)
    path_set: str = Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_.+-]{0,63}$")
    #: paths per arm: the set's first N (all when omitted)
    paths: int | None = Field(None, ge=1, le=10_000)
    #: the wall-clock limit per waypoint of an entry that has one (TRAC-IK; MoveIt's default 5 ms)
    timeout_ms: float = Field(5.0, gt=0, le=10_000)

    @field_validator("solvers")
    @classmethod
    def _solvers(cls, solvers):
        return _entries(solvers, PATH_SOLVERS, "paths")

    @model_validator(mode="after")
    def _known(self):
        if self.reference not in self.solvers:
            raise ValueError(f"reference: '{self.reference}' is not one of the track's solvers ({', '.join(self.solvers)})")
        return self


class Tracks(Strict):
    # the YAML names the track `all-solutions`; dumped by that name too (a stored config reloads as read)
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, validate_by_name=True, validate_by_alias=True,
                              serialize_by_alias=True)
    clock: ClockTrack | None = None
    throughput: ThroughputTrack | None = None
    all_solutions: SolutionsTrack | None = Field(None, alias="all-solutions")
    paths: PathsTrack | None = None

    @model_validator(mode="after")
    def _needs_clock(self):
        if self.throughput is not None and self.clock is None:
            raise ValueError("throughput runs on the clock track's arms and solvers: give tracks.clock too")
        return self


class SuiteConfig(Located):
    kind: Literal["suite"]
    pose_sets: str = Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_.+-]{0,63}$")
    problems: list[SuiteProblem] = Field(min_length=1)
    sets: list[Literal["uniform", "near-singular", "boundary", "printed"]] = Field(default_factory=lambda: list(SETS))
    poses: int | None = Field(None, ge=1)
    solvers: list[SuiteSolver] = Field(min_length=1)
    budget_per_dim: int = Field(1000, ge=1, le=MAX_BUDGET_PER_DIM)
    population: int = Field(20, ge=2, le=100_000)
    runs: int = Field(5, ge=1, le=MAX_RUNS)
    seed: int = Seed()
    targets: list[float] = Field(default_factory=lambda: list(TARGETS), min_length=1)
    #: Bootstrap of the rankings: resamples of the (problem, set, pose) instances, and the level
    #: of the Holm-corrected pairwise tests.
    bootstrap: int = Field(1000, ge=100, le=100_000)
    alpha: float = Field(0.05, gt=0, lt=0.5)
    #: Solvers run elsewhere, imported from CSV files of evaluations and best-so-far per run.
    outside: list[OutsideSolver] = Field(default_factory=list)
    #: Groups of solvers that run a subset of the cells (:class:`SolverSubset`); none: all run all.
    subsets: list[SolverSubset] = Field(default_factory=list)
    quick: QuickTier | None = None
    #: kinbench v3's tracks on the clock (IK of the suite's URDF arms); None: none.
    tracks: Tracks | None = None
    check: Literal["ci", "full"] = "full"
    _folder: Path | None = PrivateAttr(None)

    @property
    def folder_parts(self) -> tuple[str, str]:
        return (self.paper or "suites", self.name)

    @model_validator(mode="before")
    @classmethod
    def _instances(cls, data):
        """Problems with ``instances: K`` become their K geometry instances (drawn from ``seed``)."""
        if not isinstance(data, dict) or not isinstance(data.get("problems"), list):
            return data
        problems = [p.model_dump(mode="json") if isinstance(p, SuiteProblem) else p for p in data["problems"]]
        if not any(isinstance(p, dict) and p.get("instances") for p in problems):
            return data
        counts = [p.get("instances") for p in problems if isinstance(p, dict)]
        total = sum(c for c in counts if isinstance(c, int) and not isinstance(c, bool) and c > 0)
        if total > MAX_SUITE_INSTANCES:     # bounded before any geometry is drawn (~0.3 s per instance)
            raise ValueError(f"problems: {total} geometry instances in all; allowed: at most {MAX_SUITE_INSTANCES} "
                             "per suite (instances: K of every problem added up; each is drawn and checked "
                             "for degeneracy before the run)")
        seed = data.get("seed", cls.model_fields["seed"].default)
        out = []
        for i, p in enumerate(problems):
            if not (isinstance(p, dict) and p.get("instances")):
                out.append(p)
                continue
            try:                                                       # its fields first, then the draws
                checked = SuiteProblem(**p).model_dump(mode="json")
            except ValidationError as err:
                raise ValueError(f"problems[{i}].{error_line(err, None, p)}") from None
            if not isinstance(seed, int) or isinstance(seed, bool):
                raise ValueError("seed: an integer (instances are drawn from it)")
            try:
                out += instances.expand(checked, seed, f"problems[{i}]")
            except FkoptError as err:
                raise ValueError(str(err)) from None
        return {**data, "problems": out}

    @field_validator("solvers")
    @classmethod
    def _unique(cls, solvers):
        return unique_labels(solvers)

    @field_validator("problems")
    @classmethod
    def _unique_problems(cls, problems):
        names = [p.name for p in problems]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"problem names must be unique, '{dup[0]}' repeats")
        return problems

    @model_validator(mode="after")
    def _outside_names(self):
        names = [s.key for s in self.solvers] + [o.solver for o in self.outside]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"solver labels must be unique over solvers and outside, '{dup[0]}' repeats")
        return self

    @field_validator("targets")
    @classmethod
    def _targets(cls, targets):
        if any(t <= 0 for t in targets) or sorted(targets, reverse=True) != list(targets) \
                or len(set(targets)) != len(targets):
            raise ValueError("targets must be positive, distinct and in decreasing order (1e-2 ... 1e-10)")
        return targets

    @field_validator("sets")
    @classmethod
    def _sets(cls, sets):
        if not sets or len(set(sets)) != len(sets):
            raise ValueError(f"sets: one or more distinct of {', '.join(SETS)}")
        return sets

    @model_validator(mode="after")
    def _quick_names(self):
        if self.quick is None:
            return self
        if len(self.name) > MAX_QUICK_NAME:
            raise ValueError(f"name: {len(self.name)} characters; a suite with a quick: block takes at most "
                             f"{MAX_QUICK_NAME}, so that its --quick result '<name>-quick' is a folder name of at "
                             "most 64 characters (a shorter name, or no quick: block)")
        for field, known in (("problems", [p.name for p in self.problems]),
                             ("solvers", [s.key for s in self.solvers])):
            for name in getattr(self.quick, field) or []:
                if name not in known:
                    raise ValueError(f"quick.{field}: '{name}' is not one of the suite's {field} "
                                     f"({', '.join(known)})")
        return self

    @model_validator(mode="after")
    def _subsets(self):
        """Subsets name the suite's solvers, problems and sets, each solver in one subset at most,
        and only cut the suite (fewer poses and runs)."""
        seen: dict[str, str] = {}
        names = [s.name for s in self.subsets]
        solvers = [s.key for s in self.solvers]
        problems = [p.name for p in self.problems]
        for k, sub in enumerate(self.subsets):
            where = f"subsets[{k}]"
            if sub.name == FULL_BOARD or names.count(sub.name) > 1:
                raise ValueError(f"{where}.name: '{sub.name}' is taken (allowed: a name other than "
                                 f"'{FULL_BOARD}', the board of the whole suite, and the other subsets')")
            for field, known in (("solvers", solvers), ("problems", problems), ("sets", self.sets)):
                for name in getattr(sub, field) or []:
                    if name not in known:
                        raise ValueError(f"{where}.{field}: '{name}' is not one of the suite's {field} "
                                         f"(allowed: {', '.join(known)})")
                values = getattr(sub, field) or []
                if len(set(values)) != len(values):
                    raise ValueError(f"{where}.{field}: '{next(v for v in values if values.count(v) > 1)}' repeats")
            for name in sub.solvers:
                if name in seen:
                    raise ValueError(f"{where}.solvers: '{name}' is already in subset '{seen[name]}' "
                                     "(allowed: each solver in one subset at most)")
                seen[name] = sub.name
            if sub.poses is not None and self.poses is not None and sub.poses > self.poses:
                raise ValueError(f"{where}.poses: {sub.poses} (allowed: 1 to the suite's poses, {self.poses})")
            if sub.runs is not None and sub.runs > self.runs:
                raise ValueError(f"{where}.runs: {sub.runs} (allowed: 1 to the suite's runs, {self.runs})")
        return self

    def subset_of(self, solver: str) -> SolverSubset | None:
        """The subset solver label ``solver`` runs (None: the whole suite)."""
        return next((s for s in self.subsets if solver in s.solvers), None)

    def runs_of(self, solver: str) -> int:
        sub = self.subset_of(solver)
        return sub.runs if sub is not None and sub.runs is not None else self.runs

    def runs_problem(self, solver: str, problem: str) -> bool:
        sub = self.subset_of(solver)
        return sub is None or sub.problems is None or problem in sub.problems

    def board_cells(self) -> list[tuple[str, list[str]]]:
        """(board name, the solver labels whose cells define it) of every board: the whole suite's
        (its solvers without a subset, and the outside results) and one per subset."""
        free = [s.key for s in self.solvers if self.subset_of(s.key) is None] + [o.solver for o in self.outside]
        out = [(FULL_BOARD, free)] if free else []
        return out + [(s.name, list(s.solvers)) for s in self.subsets]

    @model_validator(mode="after")
    def _track_problems(self):
        clock = self.tracks.clock if self.tracks is not None else None
        if clock is not None:
            known = [p.name for p in self.problems]
            for name in clock.problems:
                if name not in known:
                    raise ValueError(f"tracks.clock.problems: '{name}' is not one of the suite's problems "
                                     f"({', '.join(known)})")
            if clock.set not in self.sets:
                raise ValueError(f"tracks.clock.set: '{clock.set}' is not one of the suite's sets ({', '.join(self.sets)})")
        for key in ("all_solutions", "paths"):
            track = getattr(self.tracks, key, None) if self.tracks is not None else None
            if track is None:
                continue
            known = [p.name for p in self.problems]
            where = f"tracks.{key.replace('_', '-')}"
            for name in track.problems:
                if name not in known:
                    raise ValueError(f"{where}.problems: '{name}' is not one of the suite's problems ({', '.join(known)})")
            if len(set(track.problems)) != len(track.problems):
                raise ValueError(f"{where}.problems: '{next(v for v in track.problems if track.problems.count(v) > 1)}' repeats")
            if key == "all_solutions" and track.set not in self.sets:
                raise ValueError(f"{where}.set: '{track.set}' is not one of the suite's sets ({', '.join(self.sets)})")
        return self

    def stored_dump(self) -> dict:
        """The config as meta.json records it: v3's fields (``tracks``, ``quick.queries``,
        a problem's ``instances``) only when set, so a v1/v2 suite's stored meta.json is what a rerun writes."""
        data = self.model_dump(mode="json")
        if data.get("tracks") is None:
            data.pop("tracks", None)
        else:                                           # v3's newer tracks, only when asked for
            for key in ("all-solutions", "paths"):
                if data["tracks"].get(key) is None:
                    data["tracks"].pop(key, None)
        if not data.get("subsets"):                     # v3's solver subsets, only when there are any
            data.pop("subsets", None)
        for key in ("queries", "paths"):
            if isinstance(data.get("quick"), dict) and data["quick"].get(key) is None:
                data["quick"].pop(key, None)
        for problem in data.get("problems") or []:      # v3's geometry instances, only when asked for
            if isinstance(problem, dict) and problem.get("instances") is None:
                problem.pop("instances", None)
        return data

    def quick_tier(self, where: str = "suite") -> "SuiteConfig":
        """The ``--quick`` subset as a config of its own (name ``<name>-quick``, no quick block)."""
        if self.quick is None:
            raise FkoptError(f"{where}: quick: missing; --quick needs a quick: block (fields: "
                             f"{', '.join(QuickTier.model_fields)})")
        q = self.quick
        data = self.model_dump(mode="json")
        # the quick tier is itself a small subset: every quick solver on every quick cell
        if len(self.name) > MAX_QUICK_NAME:      # never cut: name-quick cut to 64 would be the full result's name
            raise FkoptError(f"{where}: name: '{self.name}' is {len(self.name)} characters; --quick writes "
                             f"'<name>-quick', so a suite with a quick: block takes at most {MAX_QUICK_NAME}")
        data.update(name=f"{self.name}-quick", quick=None, check="ci", subsets=[])
        if q.problems:
            data["problems"] = [p for p in data["problems"] if p["name"] in q.problems]
        if data.get("title"):     # the suite's title counts the suite's arms, not the tier's
            data["title"] = f"{data['title']} -- quick tier: {len(data['problems'])} of its {len(self.problems)} problems"
        if q.solvers:
            data["solvers"] = [s for s in data["solvers"] if (s.get("label") or s["name"]) in q.solvers]
        for key in ("sets", "poses", "runs", "budget_per_dim"):
            if getattr(q, key) is not None:
                data[key] = getattr(q, key)
        clock = (data.get("tracks") or {}).get("clock")
        if clock is not None:
            kept = {p["name"] for p in data["problems"]}
            clock["problems"] = [p for p in clock["problems"] if p in kept]
            if q.queries is not None:
                clock["queries"] = q.queries
            if not clock["problems"] or clock["set"] not in data["sets"]:
                data["tracks"] = None if not data["tracks"].get("all-solutions") and not data["tracks"].get("paths") \
                    else {**data["tracks"], "clock": None, "throughput": None}
        for key, count in (("all-solutions", "queries"), ("paths", "paths")):
            track = (data.get("tracks") or {}).get(key)
            if track is None:
                continue
            kept = {p["name"] for p in data["problems"]}
            track["problems"] = [p for p in track["problems"] if p in kept]
            if "locked" in track:
                track["locked"] = {p: j for p, j in track["locked"].items() if p in kept}
            if getattr(q, count) is not None:
                track[count] = getattr(q, count)
            if not track["problems"]:
                data["tracks"][key] = None
        if data.get("tracks") is not None and not any(data["tracks"].get(k) for k in ("clock", "all-solutions", "paths")):
            data["tracks"] = None
        out = SuiteConfig(**data)
        out._folder = self._folder
        return out


def suite_from_dict(data: dict, where: str) -> SuiteConfig:
    try:
        return SuiteConfig(**data)
    except ValidationError as err:
        raise FkoptError(f"{where}: {error_line(err, None, data, model=SuiteConfig)}") from None


def load_suite(path: str | Path) -> SuiteConfig:
    config = suite_from_dict(load_mapping(path, "suite fields"), str(path))
    config._folder = Path(path).parent
    return config
