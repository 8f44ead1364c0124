"""The ``fkopt`` command line: a thin layer over the Python API and the experiment layer.

Every user mistake ends as one line ``fkopt: error: ...`` on stderr and exit status 2;
Ctrl-C ends with status 130. Neither prints a traceback.
"""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Optional

import numpy as np
import typer

from fkopt import registry
from fkopt.errors import FkoptError
from fkopt.files import strict_json

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="Rerunnable swarm-optimisation experiments for robot mechanism kinematics. "
                       "Start with: fkopt run configs/mao2017/tab2_tab3_fig2.yaml (writes "
                       "./fkopt-results/); the files and commands are described in README.md and docs/.")

#: Where ``fkopt run`` and ``fkopt study`` write unless given ``--out``: a git-ignored folder of the
#: current directory, so a user's own experiment never lands in the tracked ``results/`` (which
#: ``fkopt reproduce`` and ``fkopt check`` use) without asking for it with ``--out results``.
DEFAULT_OUT = Path("fkopt-results")


def _flags_without_type_tag() -> None:
    """typer (>= 0.2x) tags every option with its type in ``--help``, flags too (``--json <bool>``);
    a flag takes no value, so its tag only misleads. Options with a value keep theirs."""
    try:
        from typer.core import TyperOption
    except ImportError:           # an older typer has neither the tags nor this class
        return
    shown = getattr(TyperOption, "display_type_rich", None)
    if shown is None or getattr(shown, "_fkopt", False):
        return

    def display_type_rich(self, ctx):
        return None if getattr(self, "is_flag", False) else shown(self, ctx)
    display_type_rich._fkopt = True
    TyperOption.display_type_rich = display_type_rich


def _version(value: bool) -> None:
    if value:
        from fkopt import __version__
        from fkopt.numerics.path import version_line
        typer.echo(f"fkopt {__version__}; {version_line()}")
        raise typer.Exit()


@app.callback()
def _main_options(version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                               help="print fkopt's version and exit")):
    """Rerunnable swarm-optimisation experiments for robot mechanism kinematics."""

_flags_without_type_tag()

#: Algorithms tried in order for a single forward/inverse solve: the most reliable first.
RELIABLE = ("gabc+lm", "lm", "gabc")


def _console(stderr: bool = False):
    from rich.console import Console
    return Console(stderr=stderr, highlight=False)


def parse_assignments(text: str, option: str) -> dict[str, float]:
    """``"alpha=9,beta=13,z=622"`` -> {"alpha": 9.0, ...} with a clear error."""
    out: dict[str, float] = {}
    for part in filter(None, (p.strip() for p in text.split(","))):
        name, sep, value = part.partition("=")
        name = name.strip()
        if not sep or not name:
            raise FkoptError(f"{option}: expected name=value pairs separated by commas, got '{part}'")
        if name in out:
            raise FkoptError(f"{option}: '{name}' is given twice")
        try:
            number = float(value)
        except ValueError:
            raise FkoptError(f"{option}: '{name}' needs a number, got '{value}'") from None
        if not math.isfinite(number):
            raise FkoptError(f"{option}: '{name}' needs a finite number, got '{value.strip()}'")
        out[name] = number
    if not out:
        raise FkoptError(f"{option}: no values given")
    return out


def load_geometry(path: Optional[Path]) -> dict:
    if path is None:
        return {}
    from fkopt.files import load_mapping
    return load_mapping(path, "geometry keys")


def _mechanism(name: str, geometry: Optional[Path]):
    """Mechanism ``name`` with the overrides of a --geometry YAML file (its relative file paths,
    e.g. a URDF's, taken from the YAML's folder), or, for ``urdf``, a .urdf file itself."""
    from fkopt import mechanism
    from fkopt.registry import mechanism_class, resolve_files
    if geometry is not None and geometry.suffix.lower() == ".urdf":
        try:
            return mechanism(name, file=str(geometry))
        except FkoptError as err:
            if "name geometry." not in str(err):
                raise
            raise FkoptError(f"{err}: with a branching tree give --geometry a YAML file with "
                             f"'file: {geometry.name}', 'base:' and 'tip:'") from None
    values = load_geometry(geometry)
    if geometry is not None:
        values = resolve_files(mechanism_class(name), values, geometry.parent)
    return mechanism(name, **values)


def _default_algorithm() -> str:
    return next(a for a in RELIABLE if a in registry.ALGORITHMS)


# -- commands ------------------------------------------------------------------------------------
@app.command("list")
def list_cmd(mech: Optional[str] = typer.Argument(None, help="a mechanism: show its geometry, bounds, "
                                                              "units, pose and joint names"),
             geometry: Optional[Path] = typer.Option(None, "--geometry", help="YAML file of geometry "
                                                     "overrides (for urdf also the .urdf file itself)"),
             as_json: bool = typer.Option(False, "--json", help="print one JSON object instead of "
                                          "tables: {mechanisms, algorithms, origins}, or with MECH its "
                                          "geometry, bounds, units and names"),
             long: bool = typer.Option(False, "--long", "-l", help="the full tables: each mechanism's pose, "
                                       "joints and paper, each algorithm's parameters with their defaults, "
                                       "and where each comes from")):
    """List the mechanisms and algorithms fkopt knows: their names by kind (--long: pose, joints,
    parameters and where each comes from)."""
    if mech is not None:
        return _list_mechanism(mech, as_json, geometry)
    if geometry is not None:
        raise FkoptError("--geometry: name the mechanism it is for (fkopt list MECH --geometry FILE)")
    mechs, algos = registry.entries("mechanism"), registry.entries("algorithm")
    if as_json:
        typer.echo(strict_json({"mechanisms": [e.name for e in mechs], "algorithms": [e.name for e in algos],
                               "origins": {"mechanisms": {e.name: e.origin for e in mechs},
                                           "algorithms": {e.name: e.origin for e in algos}}}))
        return
    if not long:
        return _list_names(mechs, algos)
    from rich import box
    from rich.markup import escape
    from rich.table import Table
    # fits 80 columns: one line per unit group in a cell, borders only under the header
    table = Table(title="mechanisms (fkopt list MECH for geometry and bounds)", box=box.SIMPLE_HEAD,
                  pad_edge=False)
    for col in ("name", "kind", "pose", "joints", "paper", "from"):
        table.add_column(col, no_wrap=col in ("name", "kind"))
    for e in mechs:
        try:   # class attributes only: listing builds no mechanism (the URDF one reads a file)
            m = registry.mechanism_class(e.name)
        except FkoptError as err:
            table.add_row(e.name, "", "", "", "", escape(f"{e.origin}; error: {err}"))
            continue
        mark = "*" if m.reconstruction else ""
        table.add_row(e.name, m.kind, escape(unit_groups(m.pose_names, m.pose_units)),
                      escape(unit_groups(m.joint_names, m.joint_units)), (m.paper or "") + mark, escape(e.origin))
    con = _console()
    con.print(table)
    con.print("* a reconstruction: the paper does not print the whole model (docs/models.md)")
    table = Table(title="algorithms", box=box.SIMPLE_HEAD, pad_edge=False)
    for col in ("name", "parameters (defaults)", "from"):
        table.add_column(col)
    for e in algos:
        if e.origin.startswith("adapter"):
            table.add_row(e.name, "params: passed to the library; evaluations, workers", e.origin)
            continue
        try:
            cls = registry.algorithm_class(e.name)
        except FkoptError as err:
            table.add_row(e.name, escape(f"error: {err}"), e.origin)
            continue
        params = ", ".join(f"{k}={f.default!r}" for k, f in cls.Params.model_fields.items())
        table.add_row(e.name, escape(params), e.origin)
    con.print(table)
    typer.echo("Also: any package.module:Class subclassing fkopt's Mechanism or Algorithm\n"
               "(see docs/plugins.md).")


def _list_names(mechs, algos) -> None:
    """``fkopt list`` without --long: the names, one line per kind, to fit a screen."""
    import textwrap
    groups: dict[str, list[str]] = {}
    notes = []
    for e in mechs:
        try:   # class attributes only: listing builds no mechanism
            m = registry.mechanism_class(e.name)
        except FkoptError as err:
            notes.append(f"{e.name}: {err}")
            continue
        label = {"parallel": "parallel (fk)", "serial": "serial (ik)"}.get(m.kind, m.kind)
        groups.setdefault(label, []).append(e.name + ("*" if m.reconstruction else ""))
    lines = ["mechanisms (fkopt list MECH: its geometry, bounds, units and names)"]
    lines += _name_lines(groups)
    groups = {}
    for e in algos:
        if e.origin.startswith("adapter"):
            library = e.name.partition(":")[0]
            optional = " (optional)" if "optional" in e.origin else ""
            groups.setdefault(f"{library}{optional}", []).append(e.name)
            continue
        if not e.origin.startswith("built-in"):
            groups.setdefault("plug-ins", []).append(e.name)
            continue
        try:
            cls = registry.algorithm_class(e.name)
        except FkoptError as err:
            notes.append(f"{e.name}: {err}")
            continue
        entry = getattr(registry, "SOLVERS", {}).get(e.name)       # the registry's facts of the solver
        kind = ("exact" if getattr(entry, "track", None) == "exact" else "swarm + local" if "+" in e.name
                else "local" if getattr(cls, "local", False) else "swarm")
        groups.setdefault(kind, []).append(e.name)
    lines += ["algorithms (fkopt list --long: their parameters and defaults)"]
    lines += _name_lines(groups)
    lines.append("* a reconstruction: the paper does not print the whole model (docs/models.md). Also any "
                 "package.module:Class subclassing Mechanism or Algorithm (docs/plugins.md).")
    lines += [f"error: {n}" for n in notes]
    width = 80
    out = []
    for line in lines:
        indent = " " * (line.index(":") + 2) if line.startswith("  ") and ":" in line else "  "
        out += textwrap.wrap(line, width, subsequent_indent=indent, break_on_hyphens=False) or [""]
    typer.echo("\n".join(out))


def _name_lines(groups: dict[str, list[str]]) -> list[str]:
    if not groups:
        return []
    wide = max(len(k) for k in groups) + 1
    return [f"  {(k + ':').ljust(wide)} " + ", ".join(v) for k, v in groups.items()]


def unit_groups(names, units) -> str:
    """Names with their units, one line per run of names sharing a unit, numbered names as a
    range: ``x, y, z [m]`` / ``alpha, beta, gamma [deg]``, ``q1..q7 [deg]``."""
    import re
    groups: list[tuple[str, list[str]]] = []
    for name, unit in zip(names, units):
        if groups and groups[-1][0] == unit:
            groups[-1][1].append(name)
        else:
            groups.append((unit, [name]))
    parts = []
    for unit, members in groups:
        numbered = [re.fullmatch(r"([A-Za-z_]+)([0-9]+)", n) for n in members]
        if len(members) > 2 and all(numbered) and len({m.group(1) for m in numbered}) == 1 \
                and [int(m.group(2)) for m in numbered] == list(range(int(numbered[0].group(2)),
                                                                      int(numbered[0].group(2)) + len(members))):
            text = f"{members[0]}..{members[-1]}"
        else:
            text = ", ".join(members)
        parts.append(f"{text} [{unit}]")
    return "\n".join(parts)


def _list_mechanism(name: str, as_json: bool, geometry: Optional[Path] = None) -> None:
    m = _mechanism(name, geometry)
    d = m.describe()
    origin = next((e.origin for e in registry.entries("mechanism") if e.name == name), "direct reference")
    units = dict(zip(m.unknown_names, m.unknown_units))
    if as_json:
        typer.echo(strict_json({**d, "from": origin, "bounds_units": units}))
        return
    from rich.markup import escape
    from rich.table import Table
    con = _console()
    title = f"{name}: {m.kind} mechanism" + (f", {m.paper}" if m.paper else "") + f" ({origin})"
    con.print(f"[bold]{escape(title)}[/]")
    if m.reconstruction:
        con.print(escape(f"reconstruction: {m.reconstruction}"))
    if "chain" in d:
        con.print(escape("chain:  " + ", ".join(f"{k}={v}" for k, v in d["chain"].items())))
    con.print("pose:   " + ", ".join(f"{n} \\[{u}]" for n, u in d["pose"].items()))
    con.print("joints: " + ", ".join(f"{n} \\[{u}]" for n, u in d["joints"].items()))
    bounds = Table(title=f"workspace bounds of the unknowns ({'pose' if m.kind == 'parallel' else 'joints'})")
    for col in ("variable", "lower", "upper", "unit"):
        bounds.add_column(col, justify="right" if col in ("lower", "upper") else "left")
    for n, (lo, hi) in d["bounds"].items():
        bounds.add_row(n, f"{lo:g}", f"{hi:g}", units.get(n, ""))
    con.print(bounds)
    if d.get("chain_joints"):                          # URDF: every moving joint as the file has it
        chain = Table(title="chain joints (URDF units; a mimic joint follows its unknown: "
                            "q = multiplier * unknown + offset)")
        for col in ("joint", "type", "lower", "upper", "unit", "unknown", "multiplier", "offset"):
            chain.add_column(col, justify="right" if col in ("lower", "upper", "multiplier", "offset") else "left")
        for j in d["chain_joints"]:
            lim = j["limits"] or ("-", "-")
            chain.add_row(escape(j["name"]), j["type"], *(f"{v:g}" if v != "-" else v for v in lim), j["unit"],
                          escape(j["unknown"]), f"{j['multiplier']:g}", f"{j['offset']:g}")
        con.print(chain)
    geo = Table(title="default geometry (override with geometry: in YAML or keyword arguments)" if geometry is None
                else f"geometry: the defaults with the values of {geometry}")
    for col in ("key", "value", "description"):
        geo.add_column(col)
    fields = type(m.geometry).model_fields
    for key, value in d["geometry"].items():
        desc = fields[key].description or "" if key in fields else ""
        geo.add_row(key, escape(json.dumps(value, default=str)), escape(desc))
    con.print(geo)


JOBS_HELP = "worker processes (local) or LocalCluster workers (dask without --scheduler)"


@app.command()
def run(configs: list[Path] = typer.Argument(..., help="config file(s) of any kind: experiments, studies "
                                             "(kind: study), assembly searches, suites (kind: suite)"),
        out: Path = typer.Option(DEFAULT_OUT, "--out", help="results root; each file writes "
                                 "OUT/<paper>/<name>/ (paper 'experiments' when the file names none); "
                                 "the tracked paper results are --out results"),
        jobs: int = typer.Option(1, "--jobs", "-j", help=JOBS_HELP),
        executor: str = typer.Option("local", "--executor", help="local | dask"),
        scheduler: Optional[str] = typer.Option(None, "--scheduler", help="address of an existing Dask "
                                                "scheduler (with --executor dask)"),
        resume: bool = typer.Option(False, "--resume", help="keep the finished tasks of an interrupted run of the "
                                    "same config and run only the others (assembly searches keep none)"),
        force: bool = typer.Option(False, "--force", help="replace a stored result made from a config "
                                   "whose result-changing fields differ"),
        quiet: bool = typer.Option(False, "--quiet", "-q", help="no progress or tables")):
    """Run config files of any kind and write their tables and figures.

    Every file is validated, and every output folder checked, before anything runs. Every kind
    goes through the same runner: --jobs and --executor dask spread its tasks (an experiment's
    algorithms, a study's pose chunks, a suite's problem x solver pairs) without changing a
    number. The fields of a file are listed in docs/config-reference.md (fkopt schema prints its
    JSON Schema)."""
    import fkopt.kinbench  # noqa: F401 (registers every built-in kind of config)
    from fkopt.run.pipeline import load_any
    _run_files([(path, load_any(path)) for path in configs], out, jobs=jobs, executor=executor,
               scheduler=scheduler, resume=resume, force=force, quiet=quiet)


#: What Ctrl-C ends and how to continue it: set while a config runs, printed by :func:`main`.
_INTERRUPTED = {"hint": None}


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
    from fkopt.files import no_empty_folders_left
    folders = [out, *{out / config.folder_parts[0] for _, config in files}]
    with no_empty_folders_left(folders):
        _run_checked(files, out, jobs=jobs, executor=executor, scheduler=scheduler, resume=resume, force=force,
                     quiet=quiet, command=command, quick=quick)


def _run_checked(files, out: Path, *, jobs: int, executor: str, scheduler: str | None, resume: bool,
                 force: bool, quiet: bool, command: str, quick: bool) -> None:
    from fkopt.run.executors import validate_executor
    import fkopt.kinbench  # noqa: F401 (registers every built-in kind of config)
    from fkopt.run.pipeline import plan_config, prepare_output, run_config
    validate_executor(executor, jobs, scheduler)
    planned, folders = [], {}
    for path, config in files:    # fail on any bad file or output folder before running anything
        plan = plan_config(config, str(path), str(path))     # the one validation; run_config runs this plan
        tasks = len(plan.tasks) + len(plan.timed)
        try:
            folder = prepare_output(config, out, force)
        except FkoptError as err:
            raise FkoptError(f"{path}: {err}") from None
        if folder in folders:
            raise FkoptError(f"{path}: writes {folder}, like {folders[folder]}; paper/name must differ")
        folders[folder] = path
        planned.append((path, config, plan, tasks))
    con = _console()
    for path, config, plan, tasks in planned:
        _INTERRUPTED["hint"] = resume_hint(command, path, config, out, quick, plan.stored)
        with _progress(con, config.name, tasks, quiet) as progress:
            outcome = run_config(config, out, source=str(path), progress=progress, force=force, checked=True,
                                 jobs=jobs, executor=executor, scheduler=scheduler, resume=resume, plan=plan)
        _INTERRUPTED["hint"] = None
        if not quiet:
            _print_outcome(con, outcome, tasks)


def _clock(seconds: float) -> str:
    seconds = int(round(seconds))
    return f"{seconds // 60}m{seconds % 60:02d}s" if seconds >= 60 else f"{seconds}s"


def _eta(done: float, total: float, elapsed: float) -> str:
    """Time left at the pace so far (finished work, counting the running task's fraction)."""
    if done <= 0 or done >= total:
        return "--" if done < total else "0s"
    return _clock(elapsed * (total - done) / done)


#: Seconds between plain progress lines when stdout is not a terminal.
HEARTBEAT_S = 10.0


class _Heartbeat:
    """Plain progress lines for a stdout that is not a terminal (a log, CI, a pipe): one line at
    most every ``every`` seconds, so a long run shows it is alive without a bar's escape codes."""

    def __init__(self, con, every: float | None = None, quiet: bool = False):
        import time
        self.con, self.every, self.clock = con, HEARTBEAT_S if every is None else every, time.perf_counter
        self.start = self.last = self.clock()
        self.on = not (quiet or con.is_terminal)

    def beat(self, text) -> None:
        now = self.clock()
        if self.on and now - self.last >= self.every:
            self.last = now
            self.con.print(f"[{_clock(now - self.start)}] {text()}", highlight=False, markup=False)


class _progress:
    """Progress of one config's tasks as the runner's ``progress(label, done, total)`` callback
    (None when quiet): a rich bar with the time left on a terminal, a plain line every ~10 s
    otherwise. ``running`` hears the running task's fraction (fkopt.progress), so the bar and
    its time left move within a task too."""

    def __init__(self, con, name: str, total: int, quiet: bool):
        self.con, self.name, self.total, self.quiet = con, name, total, quiet

    def __enter__(self):
        if self.quiet:
            return None
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
        self.heart = _Heartbeat(self.con)
        self.bar = Progress(TextColumn(f"[bold]{self.name}[/]"), BarColumn(), MofNCompleteColumn(),
                            TextColumn("{task.description}"), TimeElapsedColumn(),
                            TextColumn("{task.fields[left]} left"), console=self.con, transient=True,
                            disable=not self.con.is_terminal)
        self.bar.__enter__()
        self.task = self.bar.add_task("", total=self.total, left="--")
        return self

    def __call__(self, label: str, done: float, total: int) -> None:
        elapsed = self.heart.clock() - self.heart.start
        left = _eta(done, total, elapsed)
        self.bar.update(self.task, completed=done, description=label, left=left)
        self.heart.beat(lambda: f"{self.name}: {done:.1f}/{total} tasks ({label}), about {left} left")

    running = __call__

    def __exit__(self, *exc):
        if not self.quiet:
            self.bar.__exit__(*exc)
        return False


def _print_outcome(con, outcome, tasks: int) -> None:
    from fkopt.run.kinds import config_kind
    result = outcome.result
    shown = config_kind(result.config).console          # what the kind prints after a run
    said = shown(result, outcome.folder) if shown is not None else None
    if hasattr(said, "columns"):                        # a summary table
        _print_summary(con, said, outcome.folder, outcome.wall_s)
    else:
        head, *lines = said or [""]
        con.print(f"{outcome.folder}  ({outcome.wall_s:.2f} s){head}")
        for line in lines:
            con.print(line, markup=False, highlight=False, soft_wrap=True)
    reused = tasks - len(outcome.computed)
    if 0 < reused <= tasks:
        con.print(f"resumed: {reused} finished task(s) reused, {len(outcome.computed)} computed")


@app.command()
def study(config: Path = typer.Argument(..., help="study YAML file (kind: study)"),
          out: Path = typer.Option(DEFAULT_OUT, "--out", help="results root; the study writes "
                                   "OUT/<paper>/<name>/ (paper: studies unless the file says otherwise)"),
          jobs: int = typer.Option(1, "--jobs", "-j", help=JOBS_HELP),
          executor: str = typer.Option("local", "--executor", help="local | dask"),
          scheduler: Optional[str] = typer.Option(None, "--scheduler", help="address of an existing Dask "
                                                  "scheduler (with --executor dask)"),
          resume: bool = typer.Option(False, "--resume", help="keep the finished tasks of an interrupted "
                                      "run of the same study and run only the others"),
          force: bool = typer.Option(False, "--force", help="replace a stored result made from a config "
                                     "whose result-changing fields differ"),
          quiet: bool = typer.Option(False, "--quiet", "-q", help="no progress or tables")):
    """Run a workspace study: algorithms x many poses x runs, with statistics (= fkopt run on it).

    A study file says kind: study and draws its poses (uniform, grid, waypoints, circle) instead
    of listing cases. It writes success rates, evaluations to the threshold, an ECDF, heat maps
    of 2-D grids and pairwise rank tests; mode: tracking solves trajectories step by step, each
    step warm-started from the previous one. Fields: docs/config-reference.md (study);
    examples: configs/studies/."""
    import fkopt.kinbench  # noqa: F401 (registers every built-in kind of config)
    from fkopt.run.pipeline import load_any
    cfg = load_any(config)
    if getattr(cfg, "kind", None) != "study":
        raise FkoptError(f"{config}: not a study file (kind: study); run it with: fkopt run {config}")
    _run_files([(config, cfg)], out, jobs=jobs, executor=executor, scheduler=scheduler,
               resume=resume, force=force, quiet=quiet, command="study")


@app.command()
def suite(config: Path = typer.Argument(..., help="suite YAML file (kind: suite), e.g. configs/suites/kinbench.yaml"),
          out: Path = typer.Option(DEFAULT_OUT, "--out", help="results root; writes OUT/<paper>/<name>/ "
                                   "(the tracked results/ only when asked: make bench-suite)"),
          quick: bool = typer.Option(False, "--quick", help="run the file's quick: tier (<name>-quick)"),
          jobs: int = typer.Option(1, "--jobs", "-j", help=JOBS_HELP),
          executor: str = typer.Option("local", "--executor", help="local | dask"),
          scheduler: Optional[str] = typer.Option(None, "--scheduler", help="address of a Dask scheduler"),
          resume: bool = typer.Option(False, "--resume", help="keep the finished tasks of an interrupted run"),
          force: bool = typer.Option(False, "--force", help="replace a stored result of a different config"),
          quiet: bool = typer.Option(False, "--quiet", "-q", help="no progress")):
    """Run a benchmark suite (kinbench): problems x pose sets x solvers x runs; leaderboard files
    (= fkopt run on it; --quick picks the file's quick tier)."""
    import fkopt.kinbench  # noqa: F401 (registers every built-in kind of config)
    from fkopt.run.pipeline import load_any
    cfg = load_any(config)
    if getattr(cfg, "kind", None) != "suite":
        raise FkoptError(f"{config}: not a suite file (kind: suite); run it with: fkopt run {config}")
    if quick:
        cfg = cfg.quick_tier(str(config))
    _run_files([(config, cfg)], out, jobs=jobs, executor=executor, scheduler=scheduler, resume=resume,
               force=force, quiet=quiet, command="suite", quick=quick)


SHORT = {"median_fitness": "median f", "mean_fitness": "mean f", "std_fitness": "std f",
         "success_rate": "success", "median_iterations_to_threshold": "med. it→thr",
         "mean_evaluations": "mean evals"}


def summary_rows(df, cols: list[str]) -> tuple[list[list[str]], list[str]]:
    """The printed cells of a summary and the notes under it. Many cases (more than 8): one row
    per algorithm, its success the fraction of all runs (the mean of the cases' rates: every
    case has the same runs) and the other columns medians over the cases -- a median of the
    cases' success rates printed 0 beside a median iterations to the threshold of the few cases
    that reached it. A cell with no value (no run reached the threshold) is "-", not nan."""
    import pandas as pd
    notes = []
    if df["case"].nunique() > 8:   # many cases: one line per algorithm
        cases = df["case"].nunique()
        how = {c: ("mean" if c == "success_rate" else "median") for c in cols[2:]}
        df = df.groupby("algorithm", sort=False).agg(how).reset_index()
        df.insert(0, "case", f"all {cases} cases")
        notes.append(f"over all {cases} cases: success is the fraction of all runs, the other columns "
                     "the median over the cases" + (" (med. it→thr: of the cases some run reached the "
                                                    "threshold in)" if "median_iterations_to_threshold" in cols else ""))
    rows = [["-" if isinstance(v, float) and pd.isna(v) else f"{v:.3g}" if isinstance(v, float) else str(v)
             for v in row[cols]] for _, row in df.iterrows()]
    if any("-" == cell for row in rows for cell in row[2:]):
        notes.append("-: no value (no run reached the threshold)")
    return rows, notes


def _print_summary(con, df, folder: Path, wall: float) -> None:
    from rich.table import Table
    cols = [c for c in ("case", "algorithm", *SHORT) if c in df]
    rows, notes = summary_rows(df, cols)
    table = Table(title=f"{folder}  ({wall:.2f} s)")
    for j, c in enumerate(cols):
        # values are never cut ("1.54e-…", "succe…"): each column is as wide as its widest value
        # (headers may wrap); a terminal narrower than that wraps the lines, losing nothing
        widest = max((len(r[j]) for r in rows), default=1)
        table.add_column(SHORT.get(c, c), justify="right", no_wrap=True, min_width=widest)
    for r in rows:
        table.add_row(*r)
    _print_wide(con, table)
    for note in notes:
        con.print(note, markup=False, highlight=False)


def _print_wide(con, renderable) -> None:
    """Print ``renderable`` unclipped: in a pipe (no terminal, where rich assumes 80 columns)
    or a narrow terminal the console is widened to what the table needs."""
    from rich.console import Console
    from rich.measure import Measurement
    need = Measurement.get(con, con.options.update_width(10_000), renderable).maximum
    if need > con.width:
        con = Console(width=need, highlight=False, file=con.file, force_terminal=con.is_terminal)
    con.print(renderable)


def _not_solved(message: str, data: dict, as_json: bool, units) -> None:
    """A computed answer that is not a solution within tolerance: the best answer on stdout
    (JSON with ``"solved": false``, or nothing), one line on stderr, exit status 1."""
    if as_json:
        typer.echo(strict_json(data))
    print(f"fkopt: error: {message}", file=sys.stderr)
    raise typer.Exit(1)


#: The rotations ``fkopt ik`` takes for a serial arm's target, by name (degrees; a quaternion unitless).
ARM_ROTATIONS = {
    ("alpha", "beta", "gamma"): "Z-Y-Z Euler angles, R = Rz(alpha) Ry(beta) Rz(gamma) (fkopt fk prints these)",
    ("roll", "pitch", "yaw"): "R = Rz(yaw) Ry(pitch) Rx(roll), as URDF composes rpy",
    ("qw", "qx", "qy", "qz"): "a unit quaternion (normalised)",
}


def _rotation_counts(mask: Optional[str]) -> bool:
    """Whether the orientation is part of the task (--mask names rx, ry or rz, or no --mask)."""
    return mask is None or any(part.strip() in ("rx", "ry", "rz") for part in mask.split(","))


def arm_target(m, given: dict[str, float], rotation: bool) -> np.ndarray:
    """The tip frame (4, 4) of a serial arm's ``--pose``: x, y, z and one rotation of
    :data:`ARM_ROTATIONS` by name (none when ``rotation`` is False: the identity, which no
    error then counts). Every refusal is one line naming what is allowed."""
    from fkopt.numerics import rotations
    names = set(given)
    allowed = ["x", "y", "z", *(n for group in ARM_ROTATIONS for n in group)]
    unknown = sorted(names - set(allowed))
    if unknown:
        from fkopt.files import did_you_mean
        raise FkoptError(f"--pose: unknown name '{unknown[0]}'{did_you_mean(unknown[0], allowed)}; {m.name} takes "
                         "x, y, z and one rotation: " + "; ".join(", ".join(g) for g in ARM_ROTATIONS))
    missing = [n for n in ("x", "y", "z") if n not in names]
    if missing:
        raise FkoptError(f"--pose: missing {', '.join(missing)} (the tip position, {m.pose_units[0]})")
    groups = [g for g in ARM_ROTATIONS if names & set(g)]
    if len(groups) > 1:
        raise FkoptError("--pose: give one rotation, not " + " and ".join("/".join(g) for g in groups))
    if not groups and rotation:
        raise FkoptError("--pose: missing the rotation: " + "; or ".join(", ".join(g) for g in ARM_ROTATIONS)
                         + " (or --mask x,y,z for the position only)")
    T = np.eye(4)
    T[:3, 3] = [given["x"], given["y"], given["z"]]
    if groups:
        group = groups[0]
        absent = [n for n in group if n not in names]
        if absent:
            raise FkoptError(f"--pose: {', '.join(group)} go together; missing {', '.join(absent)}")
        v = [given[n] for n in group]
        if group[0] == "qw":
            if not math.isclose(math.sqrt(sum(c * c for c in v)), 1.0, abs_tol=1e-3):
                raise FkoptError(f"--pose: qw, qx, qy, qz must be a unit quaternion (norm 1 within 1e-3), "
                                 f"got norm {math.sqrt(sum(c * c for c in v)):.6g}")
            R = rotations.quaternion_matrix(*v)
        elif group[0] == "roll":
            R = rotations.zyx(*np.radians(v))
        else:
            R = rotations.zyz(*np.radians(v))
        T[:3, :3] = rotations.to_array(R)
    return T


@app.command()
def ik(mech: str = typer.Argument(..., help="mechanism name (fkopt list)"),
       pose: str = typer.Option(..., "--pose", help="parallel mechanism: its pose names (fkopt list MECH), e.g. "
                                "alpha=9,beta=13,z=622. Serial arm: x, y, z (its length unit) and one rotation "
                                "in degrees: alpha, beta, gamma (Z-Y-Z Euler, R = Rz(alpha) Ry(beta) Rz(gamma), "
                                "as fkopt fk prints), or roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll), as "
                                "URDF composes rpy), or qw, qx, qy, qz (a unit quaternion); no rotation with "
                                "--mask x,y,z"),
       geometry: Optional[Path] = typer.Option(None, "--geometry", help="YAML file of geometry overrides "
                                               "(urdf: also the .urdf itself)"),
       algorithm: Optional[str] = typer.Option(None, "--algorithm", help="a registered swarm/local solver for "
                                               "a serial arm instead of fkopt.inverse"),
       seed: int = typer.Option(0, "--seed", min=0, help="seed of the random starts (swarm, restarts)"),
       start: Optional[str] = typer.Option(None, "--start", help="current joints of a serial arm, e.g. "
                                           "q1=10,q2=0,...: the search begins there (fkopt.inverse)"),
       mask: Optional[str] = typer.Option(None, "--mask", help="task components that count, names from "
                                          "x,y,z,rx,ry,rz (e.g. x,y,z: position only; fkopt.inverse)"),
       position_tol: float = typer.Option(1e-6, "--position-tol", help="largest accepted position error "
                                          "(the arm's length unit)"),
       orientation_tol: float = typer.Option(1e-6, "--orientation-tol", help="largest accepted geodesic "
                                             "orientation error (radians)"),
       as_json: bool = typer.Option(False, "--json", help="print one JSON object: joints, position_error "
                                    "(length unit of the arm), rotation_error_rad, solved, ..."),
       all_solutions: bool = typer.Option(False, "--all-solutions", help="every solution of the pose inside "
                                          "the limits (fkopt.inverse solutions='all'; tolerances 1e-9 unless "
                                          "given)"),
       fixed: Optional[str] = typer.Option(None, "--fixed", help="with --all-solutions: joints locked at "
                                           "values, e.g. q3=20 (a redundant arm)"),
       spread: Optional[int] = typer.Option(None, "--spread", min=1, help="with --all-solutions: samples "
                                            "per locked joint of a redundant arm's self-motion")):
    """Inverse kinematics: closed form for a parallel mechanism, fkopt.inverse for a serial arm.

    Exit 1 (one line on stderr) when the answer is not a solution within the tolerances; exit 2
    for bad input (non-finite values, a pose outside the workspace or beyond the arm's reach)."""
    m = _mechanism(mech, geometry)
    given = parse_assignments(pose, "--pose")
    serial_frame = m.kind != "parallel" and tuple(m.pose_names[3:]) == ("alpha", "beta", "gamma")
    rotation = _rotation_counts(mask)
    if serial_frame:
        target = arm_target(m, given, rotation)
        values = m.as_values(np.concatenate([target[:3, 3], [0.0, 0.0, 0.0]]), m.pose_names, "--pose")
    else:
        values = m.as_values(given, m.pose_names, "--pose")
    if m.kind == "parallel":
        if algorithm:
            raise FkoptError(f"--algorithm: '{mech}' has a closed-form inverse map; no solver is used")
        if not m.in_bounds(values):
            box = ", ".join(f"{n} [{lo:g}, {hi:g}]" for n, (lo, hi) in zip(m.pose_names, m.bounds.tolist()))
            raise FkoptError(f"--pose: outside the workspace of {mech} ({box})")
        joints = m.ik(values)
        _emit({"joints": dict(zip(m.joint_names, map(float, joints))), "residual": 0.0, "solved": True,
               "algorithm": "closed form"}, as_json, m.joint_units,
              notes={"residual": "(closed form: exact up to rounding)"})
        return
    for name, value in (("--position-tol", position_tol), ("--orientation-tol", orientation_tol)):
        if not (np.isfinite(value) and value > 0):
            raise FkoptError(f"{name}: must be a positive number, got {value}")
    if algorithm and (start or mask):
        raise FkoptError(f"{'--start' if start else '--mask'}: only with fkopt.inverse (drop --algorithm)")
    if (fixed or spread) and not all_solutions:
        raise FkoptError(f"{'--fixed' if fixed else '--spread'}: only with --all-solutions")
    if all_solutions:
        if algorithm or start:
            raise FkoptError(f"{'--algorithm' if algorithm else '--start'}: not with --all-solutions")
        _ik_all(m, target if serial_frame else values, seed, mask, position_tol, orientation_tol, fixed, spread,
                as_json)
        return
    if algorithm:
        from fkopt.kinematics.by_algorithm import inverse_by
        if serial_frame:       # the swarms' objective takes Z-Y-Z angles: the target's, exactly as given
            from fkopt.numerics.rotations import zyz_angles
            R = target[:3, :3]
            values = np.concatenate([target[:3, 3], np.degrees(zyz_angles(tuple(tuple(r) for r in R)))])
        out = inverse_by(m, values, algorithm, tol=(position_tol, orientation_tol), seed=seed).as_dict()
        out.pop("restarts")
        out["objective"] = "geodesic"
        out["algorithm"] = algorithm
        perr, rerr = out["position_error"], out["rotation_error_rad"]
    else:
        from fkopt.kinematics.solvers import inverse
        q0 = None if start is None else m.as_values(parse_assignments(start, "--start"), m.joint_names, "--start")
        # One pose per process: loading numba and its cache (~0.7 s) costs more than the compiled
        # loop saves, so the command keeps the reference path (fkopt.numerics.path).
        r = inverse(m, target if serial_frame else values, tol=(position_tol, orientation_tol), seed=seed,
                    start=q0, mask=mask, compiled=False)
        out = r.as_dict()
        out["algorithm"] = "inverse"
        perr, rerr = out["position_error"], out["rotation_error_rad"]
    unit = m.pose_units[0]
    if not rotation:            # --mask without rx, ry, rz: no rotation was sought, so none is reported
        out.pop("rotation_error_rad", None)
    if not out["solved"]:
        turn = f", orientation error {rerr:.3g} rad" if rotation else ""
        tols = f"{position_tol:g} {unit}" + (f", {orientation_tol:g} rad" if rotation else "")
        _not_solved(f"no joints within the limits reach this pose: best position error {perr:.3g} {unit}"
                    f"{turn} (tolerance{'s' if rotation else ''} {tols})", out, as_json, m.joint_units)
    _emit(out, as_json, m.joint_units,
          notes={"position_error": f"{unit} (residual: tool position |fk(q) - target|)",
                 "rotation_error_rad": "rad (residual: geodesic orientation error)"})


def _ik_all(m, values, seed, mask, position_tol, orientation_tol, fixed, spread, as_json) -> None:
    """``fkopt ik --all-solutions``: every solution (fkopt.kinematics.branches), one line each or one JSON
    object; exit 1 when there is none inside the limits."""
    from fkopt.kinematics import inverse
    given = (position_tol, orientation_tol) != (1e-6, 1e-6)          # the command's defaults
    locked = None if fixed is None else parse_assignments(fixed, "--fixed")
    extra = {k: v for k, v in (("fixed", locked), ("spread", spread)) if v is not None}
    r = inverse(m, values, solutions="all", tol=(position_tol, orientation_tol) if given else None, mask=mask,
                seed=seed, **extra)
    data = r.as_dict()
    data["count"] = len(r)
    if not len(r):
        _not_solved(f"no solution of this pose inside the joint limits (searched {r.search['starts']} starts; "
                    f"{r.search['out_of_limits']} solutions outside the limits)", data, as_json, m.joint_units)
    if as_json:
        typer.echo(strict_json(data))
        return
    unit = m.pose_units[0]
    typer.echo(f"{len(r)} solutions inside the limits ({', '.join(m.joint_names)}; "
               f"{', '.join(m.joint_units)}), each verified to {r.tol[0]:g} {unit} / {r.tol[1]:g} rad:")
    for row, pe, re in zip(r.solutions, r.position_error, r.rotation_error):
        typer.echo("  " + "  ".join(f"{v:11.6f}" for v in row) + f"   ({pe:.1e} {unit}, {re:.1e} rad)")
    typer.echo(f"search: {r.search['rule']}; {r.search['starts']} starts")


@app.command()
def fk(mech: str = typer.Argument(..., help="mechanism name (fkopt list)"),
       joints: str = typer.Option(..., "--joints", help="e.g. d1=598.85,d2=671.92,d3=629.16"),
       geometry: Optional[Path] = typer.Option(None, "--geometry", help="YAML file of geometry overrides "
                                               "(urdf: also the .urdf itself)"),
       algorithm: Optional[str] = typer.Option(None, "--algorithm", help="a registered solver (e.g. gabc+lm) "
                                               "instead of fkopt.forward"),
       seed: int = typer.Option(0, "--seed", min=0, help="seed of the random starts (swarm, restarts)"),
       tolerance: float = typer.Option(1e-9, "--tolerance", help="largest residual max |ik(pose) - joints| "
                                       "(joint units) accepted as a solution"),
       all_solutions: bool = typer.Option(False, "--all-solutions", help="every distinct real solution in the bounds"),
       as_json: bool = typer.Option(False, "--json", help="print one JSON object: pose, residual (joint "
                                    "units), solved, found_by (local newton | restarts | global search), "
                                    "evaluations")):
    """Forward kinematics: fkopt.forward for a parallel mechanism, closed form for a serial arm.

    Exit 1 (one line on stderr) when no pose within the bounds reproduces the joints within
    --tolerance (the best residual is reported); exit 2 for bad input."""
    m = _mechanism(mech, geometry)
    values = m.as_values(parse_assignments(joints, "--joints"), m.joint_names, "--joints")
    if m.kind == "serial":
        if not m.in_bounds(values):
            box = ", ".join(f"{n} [{lo:g}, {hi:g}]" for n, (lo, hi) in zip(m.joint_names, m.bounds.tolist()))
            raise FkoptError(f"--joints: outside the joint limits of {mech} ({box})")
        pose = m.fk(values)
        _emit({"pose": dict(zip(m.pose_names, map(float, pose)))}, as_json, m.pose_units)
        return
    if not (np.isfinite(tolerance) and tolerance > 0):
        raise FkoptError(f"--tolerance: must be a positive number, got {tolerance}")
    if all_solutions:
        from fkopt.kinematics.assembly_modes import all_solutions as find_all, solutions_to_dict
        found = find_all(m, values, seed=seed)
        data = solutions_to_dict(found)
        if as_json:
            typer.echo(strict_json(data))
        else:
            _console().print(f"{len(data['solutions'])} distinct solutions")
            for s in data["solutions"]:
                _console().print(s)
        return
    if algorithm:
        from fkopt.kinematics.by_algorithm import forward_by
        r = forward_by(m, values, algorithm, tol=tolerance, seed=seed)
        out = r.as_dict()
        out.pop("stage")
        out["algorithm"] = algorithm
        x = r.pose
    else:
        from fkopt.kinematics.solvers import forward
        r = forward(m, values, tol=tolerance, seed=seed)
        out = r.as_dict()
        out["found_by"] = FOUND_BY[out.pop("stage")]
        out["algorithm"] = "forward"
        x = r.pose
    rr = m.ik(x) - values
    out["fitness"] = float(np.sum(rr * rr))
    if not out["solved"]:
        _not_solved(f"no pose within the bounds reproduces these joints: best residual {out['residual']:.3g} "
                    f"(joint units; tolerance {tolerance:g}) at "
                    f"{', '.join(f'{n}={v:.6g}' for n, v in out['pose'].items())}", out, as_json, m.pose_units)
    _emit(out, as_json, m.pose_units,
          notes={"residual": "(max |ik(pose) - joints|, joint units)",
                 "fitness": "(sum of squared joint residuals)"})


#: What ``fkopt.forward``'s ``stage`` means, as ``fkopt fk`` prints it (``found_by``).
FOUND_BY = {0: "local newton", 1: "restarts", 2: "global search", -1: "none"}


def _emit(data: dict, as_json: bool, units, notes: Optional[dict] = None) -> None:
    """The answer on stdout: JSON, or one line per variable (with its unit), then one line per
    other entry, followed by its unit or meaning from ``notes``."""
    if as_json:
        typer.echo(strict_json(data))
        return
    notes = notes or {}
    key = "joints" if "joints" in data else "pose"
    for (name, value), unit in zip(data[key].items(), units):
        typer.echo(f"{name:>8} = {value:.10g} {unit}")
    for name, value in data.items():
        if isinstance(value, dict) and name != key:
            value = ", ".join(f"{k} {v}" for k, v in value.items())
        if name != key:
            text = f"{value:.6g}" if isinstance(value, float) else f"{value}"
            note = f" {notes[name]}" if name in notes else ""
            typer.echo(f"{name:>8}: {text}{note}")


@app.command("export")
def export_cmd(results: Path = typer.Argument(..., help="results folder: one experiment or a root of them"),
               fmt: str = typer.Option("ioh", "--format", help="ioh: IOHprofiler data for IOHanalyzer"),
               out: Path = typer.Option(..., "--out", help="folder to write (outside RESULTS)")):
    """Export stored results for other tools (IOHanalyzer), without rerunning anything."""
    from fkopt.tools.export import FORMATS, ioh_export
    if fmt not in FORMATS:
        raise FkoptError(f"--format: unknown format '{fmt}'; allowed: {', '.join(FORMATS)}")
    files = ioh_export(results, out)
    typer.echo(f"wrote {len(files)} IOHprofiler index files (.json) and their .dat files to {out}")


@app.command()
def bench(quick: bool = typer.Option(False, "--quick", help="short measurement (~20 s on an idle 2-core machine, "
                                     "22.6 s measured at load average 1.8; 27-29 s under heavier load; the first run after installing "
                                     "also compiles the numerics, ~25 s more)"),
          peers: bool = typer.Option(False, "--peers", help="also time NiaPy/MEALPY/... if installed"),
          out: Path = typer.Option(Path("fkopt-bench"), "--out", help="folder for bench.csv and scaling.png "
                                   "(the committed measurements are rewritten only with --out bench)"),
          section: list[str] = typer.Option([], "--section", help="run only these sections (repeatable): "
                                            "throughput, mao2017, peers, adapters, exact, kinematics, "
                                            "ik-one-pose, ik-batch, cases, swarms, fksgp, scaling (default: all but peers "
                                            "and adapters)")):
    """Measure fkopt's speed (and peers') on this machine.

    Sections: throughput (batched fitness evaluations per second), mao2017 (the paper's Tab. 3
    budget), peers (NiaPy, MEALPY, pygmo, ... on the same fitness, if installed), adapters
    (scipy's, pymoo's and NiaPy's DE through fkopt's adapters beside gabc, abc and the plug-in DE
    on kinbench's problems; with --peers or named), exact (batched
    lm), kinematics (fkopt.forward, fkopt.inverse, all assembly modes, the fk process),
    ik-one-pose and ik-batch (fkopt.inverse on 14 example-robot-data arms and the wang7dof DH arm
    beside rtb's ik_LM at 1e-6 m / 1e-6 rad, one pose per call and 1000 poses in one call, answers
    checked by pinocchio's FK, the DH arm's by rtb's DHRobot), cases (N cases x 30 runs solved together, beside a compiled C loop when a C
    compiler is there), swarms (GABC, ABC, PSO at 1 and 100 cases beside the same C loop; pygmo's
    bee_colony with a numba fitness beside the batched ABC), scaling (population and runs; draws
    scaling.png). The last line gives the seconds per section."""
    from fkopt.bench.sections import SECTIONS, run as run_bench
    from fkopt.files import output_folder
    bad = [s for s in section if s not in SECTIONS]
    if bad:
        raise typer.BadParameter(f"unknown section {bad[0]!r}; allowed: {', '.join(SECTIONS)}",
                                 param_hint="--section")
    output_folder(out)                 # a writable folder, not a file: before measuring anything
    run_bench(quick=quick, peers=peers or "peers" in section, out=out, sections=section or None)


@app.command()
def reproduce(configs: Path = typer.Option(Path("configs"), "--configs", help="folder of experiment files"),
              out: Path = typer.Option(DEFAULT_OUT / "reproduce", "--out", help="results root written (default: a "
                                       "git-ignored folder of its own; --out results rewrites the stored "
                                       "results, as make reproduce does)"),
              stored: Path = typer.Option(Path("results"), "--compare-with", help="the stored results the new "
                                          "files are compared with (the closing line and OUT/CHANGES.md)"),
              jobs: Optional[int] = typer.Option(None, "--jobs", "-j", help="worker processes for the "
                                                 "experiments' solves (default: the CPUs available; "
                                                 "1: all in this process); timings are measured "
                                                 "afterwards, one at a time"),
              quiet: bool = typer.Option(False, "--quiet", "-q", help="no progress bars and no "
                                         "closing table; errors are still printed")):
    """Run every experiment under CONFIGS into OUT (REPORT.md, TIMING.md, index.csv, CHANGES.md) and
    compare them with the stored results.

    By default OUT is fkopt-results/reproduce/ (git-ignored), so the tracked results/ stay as
    they are; the last line says how many deterministic files moved from the stored ones and
    whether fkopt check's cross-platform rules accept them. --out results rewrites the stored
    results (make reproduce)."""
    import time
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
    from rich.table import Table
    from fkopt.reproduce.changes import snapshot
    from fkopt.reproduce.report import write_report
    from fkopt.reproduce.run import default_jobs, plan, run_all

    if jobs is not None and jobs < 1:
        raise FkoptError(f"--jobs: must be at least 1, got {jobs}")
    import tempfile
    from fkopt.reproduce.changes import agreement
    planned = plan(configs, out)        # every file validated, every output checked: nothing run yet
    kept = tempfile.TemporaryDirectory(prefix="fkopt-reproduce-")   # the old files, to judge what moved
    in_place = out.resolve() == stored.resolve()
    # what the stored tree held, for CHANGES.md and the closing line: in place, the whole tree;
    # into a folder of its own, the stored results of the configs rerun (nothing else is compared)
    before = snapshot(stored, keep=Path(kept.name),
                      only=None if in_place else {"/".join(p.config.folder_parts) for p in planned})
    con = _console()
    _INTERRUPTED["hint"] = ("the configs finished so far are written; fkopt reproduce"
                            + ("" if out == DEFAULT_OUT / "reproduce" else f" --out {out}") + " starts again")
    start = time.perf_counter()
    heart = _Heartbeat(con, quiet=quiet)
    with Progress(TextColumn("{task.fields[name]}"), BarColumn(), MofNCompleteColumn(),
                  TextColumn("{task.description}"), TimeElapsedColumn(), console=con,
                  disable=quiet or not con.is_terminal) as bar:
        overall = bar.add_task("", total=len(planned), name="[bold]reproduce[/]")
        current = {"done": 0}

        def status() -> str:
            return (f"reproduce: {current['done']}/{len(planned)} configs done"
                    + (f"; {current['now']}" if current.get("now") else ""))

        class Config:     # the runner's progress callback for one config (and its running task)
            def __init__(self, p):
                self.name = f"{p.config.paper}/{p.config.name}"
                self.task = bar.add_task("", total=p.tasks, name=f"  {self.name}")

            def __call__(self, label, d, t):
                bar.update(self.task, completed=d, description=label)
                current["now"] = f"{self.name}: {d:.1f}/{t} tasks ({label})"
                heart.beat(status)
            running = __call__

        def started(p):
            current["task"] = config = Config(p)
            return config

        def finished(d):
            bar.remove_task(current.pop("task").task)
            bar.advance(overall)
            current["done"] += 1
            current["now"] = ""
            heart.beat(status)

        def solving(n, total):
            if "solving" not in current:
                current["solving"] = bar.add_task("", total=total, name="  solving experiments in parallel")
            bar.update(current["solving"], completed=n)
            current["now"] = f"solving experiments in parallel: {n}/{total}"
            heart.beat(status)
            if n == total:
                bar.remove_task(current.pop("solving"))
        done = run_all(planned, out, started=started, finished=finished,
                       jobs=default_jobs() if jobs is None else jobs, solving=solving)
    written = write_report(out, changes_since=before)     # its snapshot of the tree serves the last line too
    paths = written.paths
    total = time.perf_counter() - start
    if not quiet:
        table = Table(title=f"reproduced {len(done)} experiments in {total:.1f} s")
        for col in ("config", "results", "files", "seconds"):
            table.add_column(col)
        for d in done:
            table.add_row(str(d.path), str(d.folder), str(d.files), f"{d.wall_s:.1f}")
        con.print(table)
        con.print("report: " + ", ".join(str(p) for p in paths))
    con.print(agreement(before, out, written.after), highlight=False, markup=False)   # even with -q: what a newcomer must know
    if not in_place:
        con.print(f"reproduce: wrote {out}/ (REPORT.md, CHANGES.md); the stored {stored}/ is unchanged "
                  f"(fkopt reproduce --out {stored} rewrites it)", highlight=False, markup=False)
    kept.cleanup()


@app.command()
def schema(kind: str = typer.Argument("experiment", help="experiment | study | assembly | suite")):
    """Print the JSON Schema of a kind of config file, for editors.

    A YAML file whose first line is `# yaml-language-server: $schema=PATH` (PATH relative to the
    file: the committed copies are docs/schema/<kind>.json) is validated and completed by editors
    using yaml-language-server. Every field is described in docs/config-reference.md."""
    import fkopt.kinbench  # noqa: F401 (registers every built-in kind of config)
    from fkopt.run.config_reference import schema_text
    typer.echo(schema_text(kind), nl=False)


@app.command()
def report(results: Path = typer.Argument(Path("results"), help="results root"),
           snapshot_to: Optional[Path] = typer.Option(None, "--snapshot-to", help="only record the tree's "
                                                      "state in FILE (before a rerun such as make bench-suite)"),
           changes_since: Optional[Path] = typer.Option(None, "--changes-since", help="also write CHANGES.md: "
                                                        "what moved since the state recorded in FILE")):
    """Regenerate REPORT.md, TIMING.md and index.csv from stored results (no rerun)."""
    from fkopt.reproduce.changes import load_snapshot, save_snapshot, snapshot
    from fkopt.reproduce.report import write_report
    from fkopt.reproduce.store import Store
    Store(results).require_readable()
    if snapshot_to is not None:
        save_snapshot(snapshot(results), snapshot_to)
        typer.echo(str(snapshot_to))
        return
    before = load_snapshot(changes_since) if changes_since is not None else None
    for p in write_report(results, changes_since=before).paths:
        typer.echo(str(p))


@app.command()
def pages(results: Path = typer.Argument(Path("results"), help="results root, or one suite's folder "
                                         "(results/kinbench/kinbench-v3-robots)"),
          figures: bool = typer.Option(True, "--figures/--no-figures", help="also redraw the suites' figures "
                                       "(ECDFs, clock, scaling) from their stored tables")):
    """Rewrite every kinbench suite's pages (index.html, arms.html, rankings.html) and figures from
    its stored tables, config and meta.json: no solver runs, no table is written."""
    from fkopt.kinbench.pages import regenerate, suite_folders
    for folder in suite_folders(results):
        names = regenerate(folder, figures=figures)
        typer.echo(f"{folder}: {len(names)} files ({', '.join(n for n in names if n.endswith('.html'))})")


@app.command()
def check(results: Path = typer.Argument(Path("results"), help="results root, a paper folder "
                                         "(results/mao2017) or one experiment folder"),
          subset: str = typer.Option("all", "--subset", help="all | ci"),
          experiment: Optional[list[str]] = typer.Option(None, "--experiment", "-e",
                                                         help="PAPER/NAME to check (repeatable)"),
          allow_plugins: bool = typer.Option(False, "--allow-plugins", help="import plug-ins the stored "
                                             "configs name as package.module:Class (only for results you "
                                             "trust; registered entry points need no flag)"),
          tolerant: bool = typer.Option(False, "--tolerant",
                                        help="use the cross-platform rules even where the fingerprint "
                                             "matches (same as --tier blas)"),
          tier: str = typer.Option("auto", "--tier", help="auto (from each stored env.json) | exact | blas | any"),
          quiet: bool = typer.Option(False, "--quiet", "-q", help="print only drift and errors, not one "
                                     "line per experiment")):
    """Rerun stored results from their recorded config; exit 1 if anything drifted.

    Byte for byte where the platform fingerprint in env.json matches this machine; elsewhere
    rows no BLAS call touched stay exact and the rest follow the cross-platform rules of
    fkopt.run.compare (docs/regression.md). A missing or unreadable meta.json is a failure.
    """
    from fkopt.reproduce.check import check_experiment, select, stored_tier
    if tier not in ("auto", "exact", "blas", "any"):
        raise FkoptError(f"--tier: '{tier}' unknown; allowed: auto, exact, blas, any")
    if tolerant and tier not in ("auto", "blas"):
        raise FkoptError(f"--tolerant is --tier blas; it cannot be combined with --tier {tier}")
    forced = "blas" if tolerant else (None if tier == "auto" else tier)
    from fkopt.reproduce.store import locate
    if subset not in ("all", "ci"):
        raise FkoptError(f"--subset: '{subset}' unknown; allowed: all, ci")
    if not results.is_dir():
        raise FkoptError(f"{results}: no such results folder")
    store, paper, name = locate(results)
    exps = select(store, subset, paper, name)
    if experiment:
        wanted = set(experiment)
        exps = [e for e in exps if f"{e.paper}/{e.name}" in wanted]
        missing = wanted - {f"{e.paper}/{e.name}" for e in exps}
        if missing:
            raise FkoptError(f"--experiment: no stored experiment {sorted(missing)[0]} under {results}")
    if not exps:
        raise FkoptError(f"{results}: no stored results (folders with meta.json) to check")
    failures = []
    for e in exps:
        used = forced or stored_tier(e)
        bad = check_experiment(e, tier=used, allow_plugins=allow_plugins)
        failures += bad
        if not quiet:
            typer.echo(f"{'ok  ' if not bad else 'FAIL'} {e.paper}/{e.name} ({used} rules)")
    if failures:
        for m in failures[:20]:
            typer.echo(f"drift: {m}", err=True)
        typer.echo(f"fkopt: check failed: {len(failures)} mismatch(es) in "
                   f"{len({m.experiment for m in failures})} experiment(s); first: {failures[0]}", err=True)
        raise typer.Exit(1)
    if not quiet:
        typer.echo(f"{len(exps)} experiments match their stored results")


def _reflowed_help() -> None:
    """typer's rich help keeps the line breaks of a docstring's later paragraphs, so a paragraph
    wrapped at 100 source columns broke mid-sentence in an 80-column terminal: each command's help
    is its docstring with every paragraph on one line, for the terminal to wrap."""
    import inspect
    for info in app.registered_commands:
        if info.help is None and info.callback is not None and info.callback.__doc__:
            paragraphs = inspect.cleandoc(info.callback.__doc__).split("\n\n")
            info.help = "\n\n".join(" ".join(p.split()) for p in paragraphs)


_reflowed_help()

def main() -> None:
    """Entry point: user errors are one line and exit 2, drift exits 1, Ctrl-C exits 130."""
    def interrupted() -> str:
        hint = _INTERRUPTED["hint"]
        return "fkopt: interrupted (previous results are kept" + (f"; {hint})" if hint else ")")

    def fail(message: str) -> None:
        from fkopt.files import one_line
        print(f"fkopt: error: {one_line(message)}", file=sys.stderr)
        sys.exit(2)

    if not sys.argv[1:]:     # bare `fkopt`: the help, and success (nothing went wrong)
        sys.argv.append("--help")
    try:
        code = app(standalone_mode=False)
    except FkoptError as err:
        fail(str(err))
    except KeyboardInterrupt:
        print(interrupted(), file=sys.stderr)
        sys.exit(130)
    except MemoryError:
        fail("out of memory; reduce runs, population, iterations or cases")
    except RecursionError:
        fail("input nested too deeply")
    except OSError as err:   # the file system refused (disk full, permissions): not a bug of fkopt
        where = f"{err.filename}: " if err.filename else ""
        fail(f"{where}{err.strerror or err}")
    except Exception as err:  # click's usage errors (typer vendors click): no traceback either
        kind = type(err).__name__
        if kind == "Exit":
            sys.exit(getattr(err, "exit_code", 0))
        if kind == "Abort" and isinstance(err.__cause__, EOFError):   # click turns EOFError into Abort
            fail(f"unexpected end of a file (truncated input?): {err.__cause__ or 'EOFError'}")
        if kind == "Abort":
            print(interrupted(), file=sys.stderr)
            sys.exit(130)
        if callable(getattr(err, "format_message", None)):
            fail(f"{err.format_message()} (see fkopt --help)")
        raise
    if code == 130:   # typer (>= 0.12) turns Ctrl-C into a returned 130 when not standalone
        print(interrupted(), file=sys.stderr)
        sys.exit(130)
    if isinstance(code, int) and code:
        sys.exit(code)


if __name__ == "__main__":
    main()
