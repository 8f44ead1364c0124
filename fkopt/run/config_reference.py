"""The reference of fkopt's config files, generated from the pydantic models that validate them.

For every registered kind of file (:data:`fkopt.run.kinds.KINDS`, each with its ``model``) this
module gives

* :func:`json_schema` -- the model's JSON Schema with every field's description, unit and an
  example added (what ``fkopt schema KIND`` prints and ``docs/schema/<kind>.json`` holds, for
  editors: a YAML file whose first line is ``# yaml-language-server: $schema=<path>`` is
  validated and completed against it);
* :func:`markdown` -- ``docs/config-reference.md``: every field, its type, default, allowed
  values, unit and an example.

Types, defaults and allowed values come from the models themselves; what a field means, its
unit and its example come from :data:`FIELDS`, one entry per field of every model a config can
contain (``tests/test_config_reference.py`` fails when a model gains a field without one, and
when the committed files differ from what this module generates). Regenerate them with
``python -m fkopt.run.config_reference``.
"""
from __future__ import annotations

import json
import types
import typing
from pathlib import Path
from typing import Any, Literal, get_args, get_origin

from fkopt.errors import FkoptError
from fkopt.files import models_in
from fkopt.run.kinds import KINDS

#: What each kind of file is, for the reference's headings.
KIND_TEXT = {
    "experiment": "An experiment: listed (or random) cases of one mechanism, solved by every algorithm "
                  "for `runs` seeded runs. Run with `fkopt run FILE`. A file without `kind:` is an experiment.",
    "study": "A workspace study (`kind: study`): a generated pose set (uniform, grid, waypoints, circle) "
             "solved by every algorithm; statistics, ECDF, heat maps, tracking. Run with `fkopt study FILE`.",
    "assembly": "An assembly-mode search (`kind: assembly`): every real forward solution of one set of "
                "joints. Run with `fkopt run FILE`.",
    "suite": "A benchmark suite (`kind: suite`, kinbench): problems x frozen pose sets x solvers x runs at "
             "a budget per dimension, ranked on leaderboards. Run with `fkopt suite FILE` (docs/kinbench.md).",
}
#: Folder of the generated files, relative to the repository root.
DOCS = Path("docs")
SCHEMA_DIR = DOCS / "schema"
REFERENCE = DOCS / "config-reference.md"

_POSE = "pose variables of the mechanism (`fkopt list MECH`), in its units"
_UNKNOWN = "the mechanism's unknowns: its pose (parallel) or joints (serial), in their units"

#: model class name -> field -> (description, unit, example). Units: "" when the field has none.
FIELDS: dict[str, dict[str, tuple[str, str, Any]]] = {
    "ExperimentConfig": {
        "name": ("Name of the results folder: the run writes OUT/<paper>/<name>/. A single safe folder "
                 "name: letters, digits, `_.+-`, at most 64 characters.", "", "tab2_tab3_fig2"),
        "paper": ("Groups results: the folder OUT/<paper>/. For the reproduced papers their key (mao2017, "
                  "chang2024, wu2015, liu2008, wang7dof); `experiments` when left out.", "", "mao2017"),
        "title": ("Title of the figures and of the report section.", "", "3-RPS FK: ACO vs ABC vs GABC"),
        "description": ("Free text kept in meta.json; never changes the numbers.", "", "first try"),
        "mechanism": ("The mechanism to solve, its geometry and the search bounds.", "",
                      {"name": "3-rps", "geometry": {"ra": 274}, "bounds": {"z": [400, 700]}}),
        "objective": ("What is minimised. Parallel mechanisms: `squared` (sum of squared joint residuals, "
                      "default) or `absolute` (sum of absolute residuals). Serial arms: `paper` (position "
                      "error + Euler-angle differences, default) or `geodesic` (position error + rotation "
                      "angle). Left out: the mechanism's default.", "", "squared"),
        "algorithms": ("The algorithms to compare, each run `runs` times on every case (`fkopt list` names "
                       "them and their parameters).", "", [{"name": "gabc"}, {"name": "pso"}]),
        "population": ("Agents per run (bees, particles, ants; starts for nr/lm), unless an algorithm "
                       "overrides it.", "agents", 10),
        "iterations": ("Iterations per run, unless an algorithm overrides it.", "iterations", 600),
        "runs": ("Independent seeded runs of every algorithm on every case.", "runs", 30),
        "seed": ("Seed of everything random: run k of a (case, algorithm) always draws the same numbers.",
                 "", 2017),
        "threshold": ("Fitness counted as solved: adds success rates and iterations/evaluations to the "
                      "threshold to the tables, and draws it in the convergence figure. No threshold: no "
                      "success columns.", "fitness (the objective's value)", 1e-10),
        "stop_at_threshold": ("Stop each run when its best fitness falls below `threshold` (needs one).",
                              "", False),
        "figure_names": ("File stems of the figures, by figure kind (convergence, variables, snapshot_<t>, "
                         "extras, cases, cases_time, cases_position_error, position_error, time), to name "
                         "them after the paper figure they mirror.", "", {"convergence": "fig2"}),
        "printed": ("The paper's printed values and notes for the report, shown beside fkopt's.", "",
                    {"note": "Tab. 3"}),
        "check": ("Which regression check reruns the stored result: `ci` (every test run and `make check`) "
                  "or `full` (`make check` only, for long experiments).", "", "ci"),
        "cases": ("The targets: a list of cases, or `{random: N, seed: S}` for N poses uniform in the "
                  "bounds.", "", [{"pose": {"alpha": 9, "beta": 13, "z": 622}}]),
        "batch": ("Run all runs together as arrays (default) or one after another (`false`: per-run times, "
                  "same numbers).", "", True),
        "snapshots": ("Iterations at which the whole population is kept (figure `snapshots`).", "iterations",
                      [0, 10, 50]),
        "figures": ("Extra figures: variables (best-so-far pose vs iteration), snapshots (population "
                    "scatter), extras (algorithm records such as ACO pheromone), cases (per-case error and "
                    "time), time (time of each timed run). The convergence figure is always drawn.", "",
                    ["variables"]),
    },
    "MechanismSpec": {
        "name": ("A mechanism name (`fkopt list`), or `package.module:Class` of a plug-in.", "", "3-rps"),
        "geometry": ("Overrides of the mechanism's default geometry (`fkopt list MECH` lists the keys, "
                     "defaults and units).", "the mechanism's", {"ra": 274, "rb": 158}),
        "bounds": ("Search bounds [lower, upper] of some of " + _UNKNOWN + "; the others keep their "
                   "defaults.", "the variable's", {"z": [400, 700]}),
    },
    "CaseSpec": {
        "label": ("Name of the case in the tables (default: case-1, case-2, ...).", "", "9/13/622"),
        "pose": ("The target pose; a parallel mechanism's joints are computed from it with fkopt's inverse "
                 "map (or compared with `joints` when both are given). For a serial arm, the pose to reach.",
                 "the pose variables' units", {"alpha": 9, "beta": 13, "z": 622}),
        "joints": ("Measured joints to solve (parallel mechanisms), e.g. a paper's printed leg lengths. "
                   "With a pose too, the mismatch between them is reported in inputs.csv.", "the joints' units",
                   {"d1": 598.85, "d2": 671.92, "d3": 629.16}),
        "reference": ("Another pose to compare the solution with (e.g. the exact solution of printed joints).",
                      "the pose variables' units", {"alpha": 9.01, "beta": 12.99, "z": 622.1}),
        "reference_label": ("Name of `reference` in the tables.", "", "exact"),
        "printed": ("The paper's printed solution per algorithm label: {label: {variable: value}}.",
                    "the pose variables' units", {"gabc": {"alpha": 9.0}}),
    },
    "RandomCases": {
        "random": ("Number of cases: poses uniform in the bounds.", "cases", 50),
        "seed": ("Seed of the draw (independent of the experiment's seed).", "", 7),
    },
    "AlgorithmSpec": {
        "name": ("An algorithm (`fkopt list`): abc, abc-wang7dof (wang7dof eqs. 7-8 as printed), gabc, aco, pso, "
                 "pabc, nr, lm, dls, abc+lm, gabc+lm, "
                 "pso+lm, the exact solvers forward, inverse and exact (fkopt.forward / fkopt.inverse), "
                 "`scipy:`/`pymoo:`/`niapy:` optimisers, or `package.module:Class`.", "", "gabc"),
        "label": ("Name in the tables; needed when one algorithm appears twice. Default: the name.", "",
                  "gabc_zhu2010"),
        "params": ("The algorithm's parameters (`fkopt list --long` shows them with their defaults); unknown keys "
                   "are refused. An experiment's exact solver with `solutions: all` (inverse or exact on a serial "
                   "arm, with `fixed: {joint: value}` or `spread: K` for a redundant one; forward or exact on a "
                   "parallel mechanism: its assembly modes) searches every solution of each case once, seeded "
                   "like the case's runs, into solutions.csv (docs/experiment-files.md).", "", {"rule": "zhu2010"}),
        "population": ("This algorithm's population (number of starts for nr/lm), instead of the file's.",
                       "agents", 1),
        "iterations": ("This algorithm's iterations, instead of the file's.", "iterations", 50),
        "start": ("Start point of the local methods (nr, lm, dls): {variable: value}; default the centre of "
                  "the bounds.", "the unknowns' units", {"alpha": 0, "beta": 0, "z": 550}),
        "printed": ("The paper's printed statistics for this algorithm (mean_fitness, std_fitness, time_ms, "
                    "iterations_to_converge, ...), shown beside fkopt's.", "",
                    {"mean_fitness": 4.1e-17, "time_ms": 361.3}),
    },
    "StudyConfig": {
        "kind": ("Marks the file as a study.", "", "study"),
        "paper": ("Groups results: the folder OUT/<paper>/.", "", "studies"),
        "poses": ("The pose set, in the space of " + _UNKNOWN + ": `{uniform: N, seed: S}`, `{grid: ..., "
                  "fixed: ...}`, `{waypoints: [...], points: N}`, `{circle: {...}, points: N}`; in tracking "
                  "mode also a list of waypoint/circle trajectories.", "", {"uniform": 200, "seed": 7}),
        "runs": ("Independent seeded runs of every algorithm on every pose.", "runs", 5),
        "threshold": ("Fitness counted as solved: success rates, evaluations to target and the ECDF are "
                      "against it.", "fitness (the objective's value)", 1e-10),
        "chunk": ("Poses per task (independent mode): the unit of parallel work (`--jobs`, Dask) and of "
                  "`--resume`; never changes the numbers.", "poses", 20),
        "mode": ("`independent`: every pose solved on its own, cold. `tracking`: the poses are a trajectory "
                 "solved in order, each step warm-started from the previous solution.", "", "independent"),
        "tracking": ("Settings of tracking mode.", "", {"radius": 0.05}),
        "alpha": ("Significance level of the pairwise rank tests (after Holm's correction).", "", 0.05),
    },
    "StudyAlgorithmSpec": {
        "start": ("Start point of the local methods: a pose {variable: value}, or `centre` (the centre of "
                  "the bounds).", "the unknowns' units", "centre"),
        "warm_start": ("Tracking mode: start each step from the previous step's solution (default) or solve "
                       "it cold (a baseline).", "", True),
    },
    "UniformPoses": {
        "uniform": ("Number of poses uniform in the bounds.", "poses", 200),
        "seed": ("Seed of the draw.", "", 7),
    },
    "GridPoses": {
        "grid": ("A full grid: [lower, upper, points] per variable, the first varying slowest; a grid over "
                 "two variables also gets a heat map.", "the variables' units", {"alpha": [-20, 20, 9],
                                                                                 "beta": [-20, 20, 9]}),
        "fixed": ("Values of the variables not in the grid.", "the variables' units", {"z": 550}),
    },
    "WaypointPoses": {
        "waypoints": ("Corners of a polyline (two for a line), each a full pose.", "the variables' units",
                      [{"alpha": 0, "beta": 0, "z": 500}, {"alpha": 10, "beta": 5, "z": 600}]),
        "points": ("Poses along the polyline, equally spaced, both ends included.", "poses", 50),
    },
    "CirclePoses": {
        "circle": ("A closed circle (or ellipse) in the plane of two variables.", "",
                   {"centre": {"alpha": 0, "beta": 0, "z": 550}, "radius": 5, "plane": ["alpha", "beta"]}),
        "points": ("Poses on the circle (the first not repeated).", "poses", 40),
    },
    "CircleSpec": {
        "centre": ("Centre of the circle: a full pose.", "the variables' units", {"x": 0, "y": 0, "z": 0.8}),
        "radius": ("Radius, or [r1, r2] for an ellipse (e.g. mm and degrees).", "the plane variables' units",
                   0.05),
        "plane": ("The two variables spanning the circle's plane.", "", ["x", "y"]),
    },
    "TrackingSpec": {
        "radius": ("Half width of a swarm's warm-start box around the previous solution, as a fraction of "
                   "each variable's box width (local methods start at the previous solution itself).",
                   "fraction of the box width", 0.05),
    },
    "AssemblyConfig": {
        "kind": ("Marks the file as an assembly-mode search.", "", "assembly"),
        "paper": ("Groups results: the folder OUT/<paper>/.", "", "assembly"),
        "joints": ("The joints whose forward solutions are searched.", "the joints' units",
                   {"l1": 1.0, "l2": 1.1, "l3": 1.05, "l4": 0.95, "l5": 1.0, "l6": 1.02}),
        "seed": ("Seed of the quasi-random starts.", "", 0),
        "population": ("Starts per round of the multi-start Newton (default: the solver's own, 2000 for "
                       "6-SPS).", "starts", 2000),
        "iterations": ("Newton iterations per start.", "iterations", 60),
        "runs": ("Always 1: a search is deterministic given its seed.", "", 1),
        "tol": ("Largest residual max |ik(pose) - joints| accepted as a solution.", "joint units", 1e-9),
        "dedup": ("Two solutions closer than this (in the pose space normalised by the bounds) are one.",
                  "normalised pose distance", 1e-6),
        "expected": ("Known number of real solutions, for the report.", "solutions", 40),
        "method": ("How every solution is searched: homotopy (a general 6-6 platform: the 40 roots of a start "
                   "platform followed to this one; a certificate when 40 distinct roots arrive), restarts (the "
                   "multi-start Newton and its stopping rule), or auto (homotopy where it applies, restarts "
                   "otherwise or when a path fails).", "", "auto"),
    },
    "SuiteConfig": {
        "kind": ("Marks the file as a benchmark suite.", "", "suite"),
        "paper": ("Groups results: the folder OUT/<paper>/.", "", "kinbench"),
        "pose_sets": ("Version of the frozen pose sets under configs/suites/<pose_sets>/ (CSV files and a "
                      "manifest.json of SHA-256 checksums, verified on load).", "", "kinbench-v1"),
        "problems": ("The problems: a named mechanism (FK of a parallel mechanism, IK of a serial arm) "
                     "and its problem class, ranked together.", "",
                     [{"name": "mao2017-3rps", "problem_class": "parallel-fk-3dof", "mechanism": {"name": "3-rps"}}]),
        "sets": ("Which pose sets of the version to solve.", "", ["uniform", "near-singular"]),
        "poses": ("Poses per set (the first N of each frozen set); default all.", "poses", 10),
        "solvers": ("The solvers (any fkopt algorithm, adapter or plug-in), each with its track.", "",
                    [{"name": "gabc"}, {"name": "lm"}]),
        "budget_per_dim": ("Evaluation budget of a run: this times the problem's dimension (one analytic "
                           "Jacobian counts as one evaluation).", "evaluations per dimension", 2000),
        "targets": ("Ladder of fitness targets at which success, ERT and the ECDF are measured.",
                    "fitness (the problem's scale)", [1e-2, 1e-6, 1e-10]),
        "bootstrap": ("Bootstrap resamples of the instances for the leaderboard's confidence intervals.",
                      "resamples", 1000),
        "alpha": ("Significance level of the pairwise tests of a leaderboard table (Holm-corrected).", "", 0.05),
        "outside": ("Results of solvers run outside fkopt, ranked beside fkopt's (a CSV file or an "
                    "IOHprofiler folder).", "", [{"solver": "mytool", "track": "black-box", "file": "mytool.csv"}]),
        "quick": ("The subset `--quick` runs (and CI's check reruns): fewer problems, solvers, sets, "
                  "poses, runs or a smaller budget.", "", {"solvers": ["gabc", "lm"], "poses": 3, "runs": 3}),
        "check": ("`ci`: the test suite reruns the stored result; `full`: only `fkopt check --subset all`.",
                  "", "full"),
        "subsets": ("Groups of solvers that run fewer cells than the suite (problems, sets, poses, runs); "
                    "every board compares solvers only on the cells they all ran (docs/kinbench.md).", "",
                    [{"name": "per-point", "solvers": ["gabc", "pso"], "problems": ["ur5"], "poses": 20}]),
        "tracks": ("kinbench v3's tracks on the clock: IK of the suite's URDF arms by fkopt.inverse and "
                   "the field's solvers, ranked by wall time as ratios to a reference solver "
                   "(docs/kinbench.md).", "", {"clock": {"problems": ["ur5"], "solvers": ["fkopt.inverse", "tracik"]}}),
    },
    "Tracks": {
        "clock": ("The clock track: every solver at every timeout on every query, interleaved with the "
                  "reference.", "", {"problems": ["ur5"], "solvers": ["fkopt.inverse", "tracik"]}),
        "throughput": ("Queries per second at each batch size, for the clock's solvers that take batches "
                       "(fkopt.inverse).", "", {"batches": [1, 10, 100, 1000]}),
        "all_solutions": ("The all-solutions track (key `all-solutions`): every IK solution of a pose, recall "
                          "against the analytic sets and the union of every entry's verified answers.", "",
                          {"problems": ["ur5"], "solvers": ["fkopt.inverse-all", "eaik-all"]}),
        "paths": ("The paths track: IK along frozen paths, success and time per waypoint.", "",
                  {"problems": ["ur5"], "solvers": ["fkopt.inverse_path", "rtb-ik_LM-seeded"],
                   "path_set": "kinbench-v3-paths"}),
    },
    "ClockTrack": {
        "problems": ("The suite's problems the track runs on (URDF arms: the field's packages read URDF).",
                     "", ["ur5", "panda"]),
        "solvers": ("fkopt.inverse (the organiser's) and the field's wrappers (fkopt.adapters.field).", "",
                    ["fkopt.inverse", "tracik", "rtb-ik_NR", "pin-clik", "ikpy"]),
        "reference": ("The solver every time is divided by, measured in the same job, query by query.", "",
                      "rtb-ik_LM"),
        "timeouts_ms": ("Timeouts; an answer later than the timeout is a failure counted at the timeout.",
                        "ms", [1, 5, 20]),
        "set": ("The pose set whose frozen poses are the queries.", "", "uniform"),
        "queries": ("Queries per arm: the set's first N poses (the suite's `poses` does not cut them); "
                    "default all.", "poses", 20),
        "submissions": ("Solvers run elsewhere: per query their joints (IK) or pose (FK) and wall time beside the "
                        "reference's, verified by kinbench: fkopt's FK for IK, the mechanism's own inverse map "
                        "for FK (fkopt.kinbench.submissions).", "",
                        [{"solver": "my-ik", "file": "my-ik.csv", "machine": "i7-1185G7, 1 thread"}]),
        "fk_solvers": ("Solvers of FK on the track's 6-DOF parallel mechanisms.", "", ["fkopt.forward"]),
        "fk_reference": ("The reference of FK: scipy least_squares from random starts.", "", "scipy-least_squares"),
        "fk_timeouts_ms": ("Timeouts of FK.", "ms", [20, 100, 500]),
        "rung": ("The ladder rung (0: 5 mm/0.05 rad, 1: 1 mm/0.01 rad, 2: 1e-5 m/1e-5 rad, 3: 1e-8 m/1e-8 "
                 "rad) the time to an answer is judged at.", "", 2),
    },
    "ClockSubmission": {
        "solver": ("Name of the submitted solver on the board.", "", "my-ik"),
        "file": ("CSV of its answers per query (robot, query, q0.. for IK or x0..x5 for FK, seconds, reference_seconds), relative to "
                 "the suite file.", "", "my-ik.csv"),
        "machine": ("The machine it ran on (CPU, threads, OS).", "", "i7-1185G7, 1 thread, Ubuntu 24.04"),
        "reference": ("The reference solver timed beside it; must be the track's.", "", "rtb-ik_LM"),
        "description": ("Free text: what the solver is and how it was run.", "", "my-ik 0.3, default options"),
    },
    "ThroughputTrack": {
        "batches": ("Batch sizes (the queries repeated when fewer).", "queries per call", [1, 10, 100, 1000]),
        "repeats": ("Calls per batch size; the fastest counts.", "calls", 3),
        "fk_batches": ("Batch sizes for FK of parallel mechanisms.", "queries per call", [1, 10, 100]),
        "solvers": ("IK solvers on this track only, besides the clock's batch-taking ones (batched packages).", "",
                    ["pytorch-kinematics"]),
    },
    "SuiteProblem": {
        "name": ("Name of the problem in the tables.", "", "mao2017-3rps"),
        "problem_class": ("Problems of one class are ranked together.", "", "parallel-fk-3dof"),
        "mechanism": ("The mechanism, as in an experiment: a name, geometry and bounds.", "",
                      {"name": "3-rps", "geometry": {"ra": 274, "rb": 158}}),
        "objective": ("The objective, as in an experiment; default the mechanism's.", "", "absolute"),
        "instances": ("K seeded geometries of a parallel mechanism around this geometry, each with its "
                      "workspace box: the problem stands for `<name>-i1` ... `<name>-iK` "
                      "(docs/kinbench.md, geometry instances).", "", 10),
    },
    "SuiteSolver": {
        "track": ("black-box (fitness only), jacobian (uses Jacobians) or exact; fkopt knows its own "
                  "solvers' and the adapters' tracks, a plug-in must state its own.", "", "black-box"),
    },
    "OutsideSolver": {
        "solver": ("Name of the outside solver on the leaderboard.", "", "mytool"),
        "track": ("Its track: black-box, jacobian or exact.", "", "black-box"),
        "file": ("CSV of its runs (problem, set, pose, run, evaluations, best_so_far), relative to the "
                 "suite file.", "", "mytool.csv"),
        "ioh": ("An IOHprofiler data folder of its runs, relative to the suite file.", "", "ioh-data/mytool"),
        "algorithm": ("Which algorithm of the `ioh` folder to take when it holds several.", "", "mytool"),
        "description": ("Free text: what the solver is and how it was run.", "", "mytool 1.2, default options"),
    },
    "SolverSubset": {
        "name": ("The subset's board name (not `full`, the board of the whole suite).", "", "per-point"),
        "solvers": ("Solver labels that run only this subset's cells (each in one subset at most).", "",
                    ["gabc", "pso"]),
        "problems": ("Problems the subset's solvers run (names); default all.", "", ["ur5", "panda"]),
        "sets": ("Pose sets they run; default the suite's.", "", ["uniform"]),
        "poses": ("The first N poses of each set (at most the suite's poses).", "poses", 20),
        "runs": ("Runs per pose (at most the suite's runs).", "runs", 1),
        "description": ("Free text: why these cells (the measured cost).", "", "swarms: 20 poses per set"),
    },
    "QuickTier": {
        "problems": ("Problems of the quick tier (names); default all.", "", ["mao2017-3rps"]),
        "solvers": ("Solvers of the quick tier (labels); default all.", "", ["gabc", "lm"]),
        "sets": ("Pose sets of the quick tier; default the suite's.", "", ["uniform"]),
        "poses": ("Poses per set.", "poses", 3),
        "runs": ("Runs per pose.", "runs", 3),
        "budget_per_dim": ("Budget per dimension.", "evaluations per dimension", 500),
        "queries": ("Queries per arm of the clock track and of the all-solutions track.", "poses", 5),
        "paths": ("Paths per arm of the paths track.", "paths", 2),
    },
    "SolutionsTrack": {
        "problems": ("The suite's serial arms the track runs on.", "", ["ur5", "z1"]),
        "solvers": ("Entries of the track (fkopt.registry's all-solutions role).", "",
                    ["fkopt.inverse-all", "eaik-all", "rtb-ik_LM-restarts", "tracik-restarts"]),
        "reference": ("The entry every time is divided by, pose by pose; its median time per pose on an arm is "
                      "the budget of the entries that restart until a time has passed.", "", "fkopt.inverse-all"),
        "analytic": ("The entry whose sets are the analytic reference of recall.", "", "eaik-all"),
        "locked": ("Per problem, a joint locked in every entry at 30 % of its range (a 7-joint arm's solutions "
                   "are finite then).", "", {"panda": "panda_joint7"}),
        "set": ("The pose set whose frozen configurations are the queries.", "", "uniform"),
        "queries": ("Queries per arm: the set's first N; default all.", "poses", 40),
    },
    "PathsTrack": {
        "problems": ("The suite's serial arms the track runs on.", "", ["ur5", "panda"]),
        "solvers": ("Entries of the track (fkopt.registry's path role).", "",
                    ["fkopt.inverse_path", "rtb-ik_LM-seeded", "tracik-seeded"]),
        "reference": ("The entry every time is divided by, path by path.", "", "fkopt.inverse_path"),
        "path_set": ("The frozen path set: a folder beside the suite file (python -m fkopt.kinbench.freeze "
                     "paths SUITE.yaml writes it).", "", "kinbench-v3-paths"),
        "paths": ("Paths per arm: the set's first N; default all.", "paths", 10),
        "timeout_ms": ("Wall-clock limit per waypoint of an entry that has one (TRAC-IK); MoveIt's default.",
                       "ms", 5),
    },
}
#: Fields documented once for every model that inherits them.
SHARED = {"AssemblyConfig": "ExperimentConfig", "StudyConfig": "ExperimentConfig",
          "StudyAlgorithmSpec": "AlgorithmSpec", "SuiteConfig": "ExperimentConfig", "SuiteSolver": "AlgorithmSpec"}


def kinds() -> list[str]:
    """The registered kinds of config file (importing :mod:`fkopt.kinbench` registers all four)."""
    return list(KINDS)


def model(kind: str):
    """The pydantic model of ``kind`` (experiment, study, assembly, suite)."""
    if kind not in KINDS:
        raise FkoptError(f"schema: unknown kind '{kind}'; allowed: {', '.join(KINDS)}")
    return KINDS[kind].model


def field_doc(model_name: str, field: str) -> tuple[str, str, Any] | None:
    """(description, unit, example) of a field, looking through :data:`SHARED`."""
    name = model_name
    while name is not None:
        if field in FIELDS.get(name, {}):
            return FIELDS[name][field]
        name = SHARED.get(name)
    return None


def models_of(kind: str) -> list:
    """Every model a file of ``kind`` can contain, the top-level one first (no repeats)."""
    seen, todo = [], [model(kind)]
    while todo:
        m = todo.pop(0)
        if m in seen:
            continue
        seen.append(m)
        for f in m.model_fields.values():
            todo += models_in(f.annotation)
    return seen


def _type_text(annotation) -> str:
    origin = get_origin(annotation)
    if annotation is type(None):
        return "null"
    if origin is Literal:
        return " | ".join(json.dumps(a) if not isinstance(a, str) else a for a in get_args(annotation))
    if origin in (typing.Union, types.UnionType):
        return " or ".join(_type_text(a) for a in get_args(annotation))
    if origin is dict:
        k, v = get_args(annotation)
        return f"mapping {_type_text(k)} → {_type_text(v)}"
    if origin is list:
        return f"list of {_type_text(get_args(annotation)[0])}"
    if origin is tuple:
        return "[" + ", ".join(_type_text(a) for a in get_args(annotation)) + "]"
    if isinstance(annotation, type):
        names = {"str": "text", "int": "integer", "float": "number", "bool": "true | false", "Any": "any"}
        if hasattr(annotation, "model_fields"):
            return f"[{annotation.__name__}](#{annotation.__name__.lower()})"
        return names.get(annotation.__name__, annotation.__name__)
    return "any" if annotation is Any else str(annotation)


def _limits(field) -> str:
    words = {"ge": "≥", "gt": ">", "le": "≤", "lt": "<", "min_length": "length ≥", "max_length": "length ≤"}
    out = []
    for meta in field.metadata:
        for attr, word in words.items():
            value = getattr(meta, attr, None)
            if value is not None:
                out.append(f"{word} {value:,}" if isinstance(value, int) else f"{word} {value:g}")
    return ", ".join(out)


def _default(field) -> str:
    if field.is_required():
        return "required"
    value = field.default_factory() if field.default_factory is not None else field.default
    if hasattr(value, "model_dump"):
        value = value.model_dump(mode="json")
    return "`" + json.dumps(value) + "`"


def _example_yaml(name: str, example) -> str:
    """``name: value`` as one line of YAML (flow style)."""
    import yaml
    value = yaml.safe_dump(example, default_flow_style=True, sort_keys=False, width=1000).strip()
    return f"{name}: {value.removesuffix('...').strip()}"


def json_schema(kind: str) -> dict:
    """The JSON Schema of ``kind`` with descriptions (including units) and examples of every field."""
    m = model(kind)
    schema = m.model_json_schema()
    by_name = {x.__name__: x for x in models_of(kind)}
    parts = [(m.__name__, schema)] + [(name, d) for name, d in schema.get("$defs", {}).items()]
    for name, part in parts:
        if name not in by_name:
            continue
        for field, prop in part.get("properties", {}).items():
            doc = field_doc(name, field)
            if doc is None:
                continue
            text, unit, example = doc
            prop["description"] = text + (f" Unit: {unit}." if unit else "")
            prop["examples"] = [example]
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", **schema,
            "title": f"fkopt {kind} file", "description": KIND_TEXT[kind].replace("`", "")}


def schema_text(kind: str) -> str:
    return json.dumps(json_schema(kind), indent=2, ensure_ascii=False) + "\n"


def markdown() -> str:
    """docs/config-reference.md: one section per kind, one table per model, one row per field."""
    lines = ["# Config reference", "",
             "Generated by `python -m fkopt.run.config_reference` from the pydantic models that validate the files "
             "(do not edit; `tests/test_config_reference.py` checks it is current). Every file is YAML; "
             "unknown fields, NaN and infinity are refused with one line naming the file and the field.",
             "",
             "Editors that speak yaml-language-server validate and complete a file whose first line names its "
             "schema, e.g. `# yaml-language-server: $schema=../../docs/schema/experiment.json` (a path "
             "relative to the file, or a URL). The schemas are in [schema/](schema/), and `fkopt schema KIND` "
             "prints them.", ""]
    for kind in KINDS:
        lines += [f"- [{kind}](#{kind}-files): {KIND_TEXT[kind]}"]
    lines.append("")
    documented: set[str] = set()
    for kind in KINDS:
        lines += [f"## {kind} files", "", KIND_TEXT[kind],
                  f"Schema: [schema/{kind}.json](schema/{kind}.json).", ""]
        for m in models_of(kind):
            if m.__name__ in documented:
                lines += [f"### {m.__name__} ({kind})", "", f"As in [{m.__name__}](#{m.__name__.lower()}) above.", ""]
                continue
            documented.add(m.__name__)
            lines += [f"### {m.__name__}", ""]
            if m is model(kind):
                lines += [f"The top level of {'an' if kind[0] in 'aeiou' else 'a'} {kind} file.", ""]
            lines += ["| field | type | default | allowed | unit | meaning | example |",
                      "|---|---|---|---|---|---|---|"]
            for name, field in m.model_fields.items():
                text, unit, example = field_doc(m.__name__, name) or ("", "", None)
                key = field.alias or name          # the name a file uses (tracks' `all-solutions`)
                cells = [f"`{key}`", _type_text(field.annotation), _default(field), _limits(field) or "",
                         unit, text, f"`{_example_yaml(key, example)}`"]
                lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
            lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def generated(root: Path = Path(".")) -> dict[Path, str]:
    """Every generated file (path under ``root``) and its text."""
    files = {root / REFERENCE: markdown()}
    for kind in KINDS:
        files[root / SCHEMA_DIR / f"{kind}.json"] = schema_text(kind)
    return files


def write(root: Path = Path(".")) -> list[Path]:
    written = []
    for path, text in generated(root).items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
        written.append(path)
    return written


if __name__ == "__main__":
    import fkopt.kinbench  # noqa: F401  (the script's entry: registers every built-in kind)
    for p in write(Path(__file__).resolve().parents[2]):
        print(p)
