"""The commands that run config files: ``fkopt run`` (any kind), ``fkopt study`` and ``fkopt suite``
(the same on one file of that kind), and ``fkopt schema`` (the JSON Schema of a kind's files).
Every file is validated, and every output folder checked, before anything runs.

The engine (:mod:`fkopt.run.pipeline`) and the kinds it runs (:mod:`fkopt.kinbench` registers
every built-in kind) are imported inside the commands: they pull pandas, pydantic and the
kinds' outputs, which ``fkopt --help``, ``fkopt ik`` and ``fkopt fk`` never use
(docs/design.md, "Start-up")."""
from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from fkopt.cli.display import RunProgress, print_outcome
from fkopt.cli.entry_point import DEFAULT_OUT, INTERRUPTED, app, console
from fkopt.errors import FkoptError
from fkopt.files import no_empty_folders_left


def _engine():
    """The engine (:mod:`fkopt.run.pipeline`) with every built-in kind of config registered."""
    import fkopt.kinbench  # noqa: F401  # lazy: registers every built-in kind of config (start-up)
    from fkopt.run import pipeline  # lazy: the engine pulls pandas (start-up of the light commands)
    return pipeline


JOBS_HELP = "worker processes (local) or LocalCluster workers (dask without --scheduler)"
#: Options fkopt run, study and suite share (typer reads each as a declaration, never changes it).
JOBS = typer.Option(1, "--jobs", "-j", help=JOBS_HELP)
EXECUTOR = typer.Option("local", "--executor", help="local | dask")
SCHEDULER = typer.Option(None, "--scheduler", help="address of an existing Dask scheduler (with --executor dask)")
FORCE = typer.Option(False, "--force", help="replace a stored result made from a config whose result-changing "
                     "fields differ")
QUIET = typer.Option(False, "--quiet", "-q", help="no progress or tables")


@app.command()
def run(configs: list[Path] = typer.Argument(..., help="config file(s) of any kind: experiments, studies "
                                             "(kind: study), assembly searches, suites (kind: suite)"),
        out: Path = typer.Option(DEFAULT_OUT, "--out", help="results root; each file writes "
                                 "OUT/<paper>/<name>/ (paper 'experiments' when the file names none); "
                                 "the tracked paper results are --out results"),
        jobs: int = JOBS, executor: str = EXECUTOR, scheduler: Optional[str] = SCHEDULER,
        resume: bool = typer.Option(False, "--resume", help="keep the finished tasks of an interrupted run of the "
                                    "same config and run only the others (assembly searches keep none)"),
        force: bool = FORCE, quiet: bool = QUIET):
    """Run config files of any kind and write their tables and figures.

    Every file is validated, and every output folder checked, before anything runs. Every kind
    goes through the same runner: --jobs and --executor dask spread its tasks (an experiment's
    algorithms, a study's pose chunks, a suite's problem x solver pairs) without changing a
    number. The fields of a file are listed in docs/config-reference.md (fkopt schema prints its
    JSON Schema)."""
    _run_files([(path, _engine().load_any(path)) for path in configs], out, jobs=jobs, executor=executor,
               scheduler=scheduler, resume=resume, force=force, quiet=quiet)


def _file_of_kind(command: str, path: Path):
    """The config of ``path`` when it is a file of the kind the command is named after (``fkopt
    study``, ``fkopt suite``): the registry's kind of that name, not a test of the file's text."""
    pipeline = _engine()
    config = pipeline.load_any(path)
    if pipeline.config_kind(config) is not pipeline.kind_of(command):
        raise FkoptError(f"{path}: not a {command} file (kind: {command}); run it with: fkopt run {path}")
    return config


def resume_hint(command: str, path, config, out: Path, quick: bool = False, stored: bool = True) -> str:
    """The command that continues an interrupted run of ``config``, as it works: a kind whose plan
    keeps task files (``stored``: experiments, studies, suites; ``.<name>.partial``) reuses them with
    the command the user ran and ``--resume``; an assembly search keeps none and starts again."""
    kind = getattr(config, "kind", None) or "experiment"
    where = "" if out == DEFAULT_OUT else f" --out {out}"
    if stored:
        again = f"fkopt {command} {path}{' --quick' if quick else ''}{where} --resume"
        return f"the finished tasks of this {kind} are kept: {again} continues"
    return f"an {kind} keeps no finished tasks: fkopt {command} {path}{where} starts it again"


def _run_files(files, out: Path, *, jobs: int, executor: str, scheduler: str | None, resume: bool,
               force: bool, quiet: bool, command: str = "run", quick: bool = False) -> None:
    """Validate every (path, config) and check every output folder, then run them in order.
    Interrupted or failed, it leaves no folder it created empty (``OUT/<paper>/``)."""
    folders = [out, *{out / config.folder_parts[0] for _, config in files}]
    with no_empty_folders_left(folders):
        _run_checked(files, out, jobs=jobs, executor=executor, scheduler=scheduler, resume=resume, force=force,
                     quiet=quiet, command=command, quick=quick)


def _run_checked(files, out: Path, *, jobs: int, executor: str, scheduler: str | None, resume: bool,
                 force: bool, quiet: bool, command: str, quick: bool) -> None:
    from fkopt.run.executors import validate_executor  # lazy: the engine's executors (start-up)
    pipeline = _engine()
    validate_executor(executor, jobs, scheduler)
    planned, folders = [], {}
    for path, config in files:    # fail on any bad file or output folder before running anything
        plan = pipeline.plan_config(config, str(path), str(path))     # the one validation; run_config runs this plan
        tasks = len(plan.tasks) + len(plan.timed)
        try:
            folder = pipeline.prepare_output(config, out, force)
        except FkoptError as err:
            raise FkoptError(f"{path}: {err}") from None
        if folder in folders:
            raise FkoptError(f"{path}: writes {folder}, like {folders[folder]}; paper/name must differ")
        folders[folder] = path
        planned.append((path, config, plan, tasks))
    con = console()
    for path, config, plan, tasks in planned:
        INTERRUPTED["hint"] = resume_hint(command, path, config, out, quick, plan.stored)
        with RunProgress(con, config.name, tasks, quiet) as progress:
            outcome = pipeline.run_config(config, out, source=str(path), progress=progress, force=force, checked=True,
                                 jobs=jobs, executor=executor, scheduler=scheduler, resume=resume, plan=plan)
        INTERRUPTED["hint"] = None
        if not quiet:
            print_outcome(con, outcome, tasks)


@app.command()
def study(config: Path = typer.Argument(..., help="study YAML file (kind: study)"),
          out: Path = typer.Option(DEFAULT_OUT, "--out", help="results root; the study writes "
                                   "OUT/<paper>/<name>/ (paper: studies unless the file says otherwise)"),
          jobs: int = JOBS, executor: str = EXECUTOR, scheduler: Optional[str] = SCHEDULER,
          resume: bool = typer.Option(False, "--resume", help="keep the finished tasks of an interrupted "
                                      "run of the same study and run only the others"),
          force: bool = FORCE, quiet: bool = QUIET):
    """Run a workspace study: algorithms x many poses x runs, with statistics (= fkopt run on it).

    A study file says kind: study and draws its poses (uniform, grid, waypoints, circle) instead
    of listing cases. It writes success rates, evaluations to the threshold, an ECDF, heat maps
    of 2-D grids and pairwise rank tests; mode: tracking solves trajectories step by step, each
    step warm-started from the previous one. Fields: docs/config-reference.md (study);
    examples: configs/studies/."""
    cfg = _file_of_kind("study", config)
    _run_files([(config, cfg)], out, jobs=jobs, executor=executor, scheduler=scheduler,
               resume=resume, force=force, quiet=quiet, command="study")


@app.command()
def suite(config: Path = typer.Argument(..., help="suite YAML file (kind: suite), e.g. configs/suites/kinbench.yaml"),
          out: Path = typer.Option(DEFAULT_OUT, "--out", help="results root; writes OUT/<paper>/<name>/ "
                                   "(the tracked results/ only when asked: make bench-suite)"),
          quick: bool = typer.Option(False, "--quick", help="run the file's quick: tier (<name>-quick)"),
          jobs: int = JOBS, executor: str = EXECUTOR,
          scheduler: Optional[str] = typer.Option(None, "--scheduler", help="address of a Dask scheduler"),
          resume: bool = typer.Option(False, "--resume", help="keep the finished tasks of an interrupted run"),
          force: bool = typer.Option(False, "--force", help="replace a stored result of a different config"),
          quiet: bool = typer.Option(False, "--quiet", "-q", help="no progress")):
    """Run a benchmark suite (kinbench): problems x pose sets x solvers x runs; leaderboard files
    (= fkopt run on it; --quick picks the file's quick tier)."""
    cfg = _file_of_kind("suite", config)
    if quick:
        cfg = cfg.quick_tier(str(config))
    _run_files([(config, cfg)], out, jobs=jobs, executor=executor, scheduler=scheduler, resume=resume,
               force=force, quiet=quiet, command="suite", quick=quick)


@app.command()
def schema(kind: str = typer.Argument("experiment", help="experiment | study | assembly | suite")):
    """Print the JSON Schema of a kind of config file, for editors.

    A YAML file whose first line is `# yaml-language-server: $schema=PATH` (PATH relative to the
    file: the committed copies are docs/schema/<kind>.json) is validated and completed by editors
    using yaml-language-server. Every field is described in docs/config-reference.md."""
    _engine()                    # every built-in kind registered: each has its schema
    from fkopt.run.config_reference import schema_text  # lazy: the config reference (pydantic models of every kind)
    typer.echo(schema_text(kind), nl=False)
