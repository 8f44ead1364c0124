"""The ``fkopt`` command line: a thin layer over the Python API and the experiment layer.

Every user mistake ends as one line ``fkopt: error: ...`` on stderr and exit status 2;
Ctrl-C ends with status 130. Neither prints a traceback.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Optional

import numpy as np
import typer

from . import registry
from .errors import FkoptError

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="Rerunnable swarm-optimisation experiments for robot mechanism kinematics.")

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
        if not sep:
            raise FkoptError(f"{option}: expected name=value pairs separated by commas, got '{part}'")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise FkoptError(f"{option}: '{name.strip()}' needs a number, got '{value}'") from None
    if not out:
        raise FkoptError(f"{option}: no values given")
    return out


def load_geometry(path: Optional[Path]) -> dict:
    if path is None:
        return {}
    import yaml
    try:
        data = yaml.safe_load(path.read_text())
    except OSError as err:
        raise FkoptError(f"{path}: cannot read ({err.strerror})") from None
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark else ""
        raise FkoptError(f"{path}: malformed YAML{where}") from None
    if not isinstance(data, dict):
        raise FkoptError(f"{path}: expected a mapping of geometry keys")
    return data


def _mechanism(name: str, geometry: Optional[Path]):
    from . import mechanism
    return mechanism(name, **load_geometry(geometry))


def _default_algorithm() -> str:
    return next(a for a in RELIABLE if a in registry.ALGORITHMS)


# -- commands ------------------------------------------------------------------------------------
@app.command("list")
def list_cmd(mech: Optional[str] = typer.Argument(None, help="a mechanism: show its geometry, bounds, "
                                                              "units, pose and joint names"),
             as_json: bool = typer.Option(False, "--json", help="machine-readable output")):
    """List the mechanisms and algorithms fkopt knows, and where each comes from."""
    if mech is not None:
        return _list_mechanism(mech, as_json)
    mechs, algos = registry.entries("mechanism"), registry.entries("algorithm")
    if as_json:
        typer.echo(json.dumps({"mechanisms": [e.name for e in mechs], "algorithms": [e.name for e in algos],
                               "origins": {"mechanisms": {e.name: e.origin for e in mechs},
                                           "algorithms": {e.name: e.origin for e in algos}}}))
        return
    from rich.markup import escape
    from rich.table import Table
    table = Table(title="mechanisms (fkopt list MECH for geometry and bounds)")
    for col in ("name", "kind", "pose", "joints", "paper", "from"):
        table.add_column(col, no_wrap=True)
    for e in mechs:
        try:   # class attributes only: listing builds no mechanism (the URDF one reads a file)
            m = registry.mechanism_class(e.name)
        except FkoptError as err:
            table.add_row(e.name, "", "", "", "", escape(f"{e.origin}; error: {err}"))
            continue
        mark = " (reconstruction)" if m.reconstruction else ""
        table.add_row(e.name, m.kind, ", ".join(f"{n} \\[{u}]" for n, u in zip(m.pose_names, m.pose_units)),
                      ", ".join(f"{n} \\[{u}]" for n, u in zip(m.joint_names, m.joint_units)),
                      (m.paper or "") + mark, e.origin)
    con = _console()
    _print_wide(con, table)     # one line per mechanism, even in a pipe
    table = Table(title="algorithms")
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
    typer.echo("Also: any package.module:Class subclassing fkopt's Mechanism or Algorithm (see README, Plug-ins).")


def _list_mechanism(name: str, as_json: bool) -> None:
    m = registry.mechanism_class(name)()
    d = m.describe()
    origin = next((e.origin for e in registry.entries("mechanism") if e.name == name), "direct reference")
    units = dict(zip(m.unknown_names, m.unknown_units))
    if as_json:
        typer.echo(json.dumps({**d, "from": origin, "bounds_units": units}, default=str))
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
    geo = Table(title="default geometry (override with geometry: in YAML or keyword arguments)")
    for col in ("key", "value", "description"):
        geo.add_column(col)
    fields = type(m.geometry).model_fields
    for key, value in d["geometry"].items():
        desc = fields[key].description or "" if key in fields else ""
        geo.add_row(key, escape(json.dumps(value, default=str)), escape(desc))
    con.print(geo)


@app.command()
def run(configs: list[Path] = typer.Argument(..., help="experiment YAML file(s)"),
        out: Path = typer.Option(Path("results"), "--out", help="results root; each experiment "
                                 "writes OUT/<paper>/<name>/"),
        quiet: bool = typer.Option(False, "--quiet", "-q", help="no progress or tables")):
    """Run experiment files and write their tables and figures."""
    from .experiment.reports import summary_table, write_experiment
    from .experiment.runner import run_experiment, validate_experiment

    loaded = [(path, _experiment_file(path)) for path in configs]
    for path, config in loaded:          # fail on any bad file before running anything
        try:
            validate_experiment(config)
        except FkoptError as err:
            raise FkoptError(f"{path}: {err}") from None
    con = _console()
    for path, config in loaded:
        if quiet:
            er = run_experiment(config, source=str(path))
        else:
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
            with Progress(TextColumn(f"[bold]{config.name}[/]"), BarColumn(), MofNCompleteColumn(),
                          TextColumn("{task.description}"), TimeElapsedColumn(), console=con,
                          transient=True) as bar:
                task = bar.add_task("", total=len(config.algorithms) * _n_cases(config))
                er = run_experiment(config, source=str(path),
                                    progress=lambda label, done, total: bar.update(task, completed=done,
                                                                                   description=label))
        folder = write_experiment(er, out)
        if not quiet:
            _print_summary(con, summary_table(er), folder, er.wall_s)


def _n_cases(config) -> int:
    return getattr(config.cases, "random", None) or len(config.cases)


def _experiment_file(path: Path):
    from .study.config import StudyConfig, load_any
    config = load_any(path)
    if isinstance(config, StudyConfig):
        raise FkoptError(f"{path}: a study file (kind: study); run it with: fkopt study {path}")
    return config


@app.command()
def study(config: Path = typer.Argument(..., help="study YAML file (kind: study)"),
          out: Path = typer.Option(Path("results"), "--out", help="results root; the study writes "
                                   "OUT/<paper>/<name>/ (paper: studies unless the file says otherwise)"),
          jobs: int = typer.Option(1, "--jobs", "-j", help="worker processes (local) or LocalCluster "
                                   "workers (dask without --scheduler)"),
          executor: str = typer.Option("local", "--executor", help="local | dask"),
          scheduler: Optional[str] = typer.Option(None, "--scheduler", help="address of an existing Dask "
                                                  "scheduler (with --executor dask)"),
          resume: bool = typer.Option(False, "--resume", help="keep the finished tasks of an interrupted "
                                      "run of the same study and run only the others"),
          quiet: bool = typer.Option(False, "--quiet", "-q", help="no progress or tables")):
    """Run a workspace study: algorithms x poses x runs, statistics, tracking (see fkopt.study)."""
    from .study.config import load_study
    from .study.executors import validate_executor
    from .study.reports import summary_table
    from .study.runner import plan_tasks, run_study, validate_study

    cfg = load_study(config)
    validate_executor(executor, jobs, scheduler)
    try:
        _, poses = validate_study(cfg)
    except FkoptError as err:
        raise FkoptError(f"{config}: {err}") from None
    kwargs = dict(jobs=jobs, executor=executor, scheduler=scheduler, resume=resume, source=str(config))
    if quiet:
        result = run_study(cfg, out, **kwargs)
    else:
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
        con = _console()
        with Progress(TextColumn(f"[bold]{cfg.name}[/]"), BarColumn(), MofNCompleteColumn(),
                      TextColumn("{task.description}"), TimeElapsedColumn(), console=con,
                      transient=True) as bar:
            task = bar.add_task("", total=len(plan_tasks(cfg, len(poses))))
            result = run_study(cfg, out, progress=lambda label, done, total: bar.update(
                task, completed=done, description=label), **kwargs)
        reused = len(plan_tasks(cfg, len(poses))) - len(result.computed)
        _print_summary(con, summary_table(result), result.folder, result.wall_s)
        if reused:
            con.print(f"resumed: {reused} finished task(s) reused, {len(result.computed)} computed")


SHORT = {"median_fitness": "median f", "mean_fitness": "mean f", "std_fitness": "std f",
         "success_rate": "success", "median_iterations_to_threshold": "med. it→thr",
         "mean_evaluations": "mean evals"}


def _print_summary(con, df, folder: Path, wall: float) -> None:
    from rich.table import Table
    cols = [c for c in ("case", "algorithm", *SHORT) if c in df]
    if df["case"].nunique() > 8:   # many cases: one line per algorithm
        df = df.groupby("algorithm", sort=False).agg({c: "median" for c in cols[2:]}).reset_index()
        df.insert(0, "case", "median over cases")
    rows = [[f"{v:.3g}" if isinstance(v, float) else str(v) for v in row[cols]] for _, row in df.iterrows()]
    table = Table(title=f"{folder}  ({wall:.2f} s)")
    for j, c in enumerate(cols):
        # values are never cut ("1.54e-…", "succe…"): each column is as wide as its widest value
        # (headers may wrap); a terminal narrower than that wraps the lines, losing nothing
        widest = max((len(r[j]) for r in rows), default=1)
        table.add_column(SHORT.get(c, c), justify="right", no_wrap=True, min_width=widest)
    for r in rows:
        table.add_row(*r)
    _print_wide(con, table)


def _print_wide(con, renderable) -> None:
    """Print ``renderable`` unclipped: in a pipe (no terminal, where rich assumes 80 columns)
    or a narrow terminal the console is widened to what the table needs."""
    from rich.console import Console
    from rich.measure import Measurement
    need = Measurement.get(con, con.options.update_width(10_000), renderable).maximum
    if need > con.width:
        con = Console(width=need, highlight=False, file=con.file, force_terminal=con.is_terminal)
    con.print(renderable)


@app.command()
def ik(mech: str = typer.Argument(..., help="mechanism name (fkopt list)"),
       pose: str = typer.Option(..., "--pose", help="e.g. alpha=9,beta=13,z=622"),
       geometry: Optional[Path] = typer.Option(None, "--geometry", help="YAML file of geometry overrides"),
       algorithm: Optional[str] = typer.Option(None, "--algorithm", help="solver for a serial arm"),
       seed: int = typer.Option(0, "--seed"),
       as_json: bool = typer.Option(False, "--json")):
    """Inverse kinematics: closed form for a parallel mechanism, solved for a serial arm."""
    m = _mechanism(mech, geometry)
    values = m.vector(parse_assignments(pose, "--pose"), m.pose_names, "--pose")
    if m.kind == "parallel":
        if algorithm:
            raise FkoptError(f"--algorithm: '{mech}' has a closed-form inverse map; no solver is used")
        joints = m.ik(values)
        _emit({"joints": dict(zip(m.joint_names, map(float, joints)))}, as_json, m.joint_units)
        return
    from . import problems, solve
    problem = problems.ik_problem(m, values)
    name = algorithm or _default_algorithm()
    res = solve(problem, name, population=50, iterations=500, runs=1, seed=seed)
    q = res.x[0]
    out = {"joints": dict(zip(m.joint_names, map(float, q))), "fitness": float(res.fitness[0]),
           "objective": problem.objective, "algorithm": name}
    if hasattr(problem, "position_error"):
        out["position_error"] = float(problem.position_error(q))
        out["rotation_error_deg"] = float(problem.rotation_error(q))
    _emit(out, as_json, m.joint_units)


@app.command()
def fk(mech: str = typer.Argument(..., help="mechanism name (fkopt list)"),
       joints: str = typer.Option(..., "--joints", help="e.g. d1=598.85,d2=671.92,d3=629.16"),
       geometry: Optional[Path] = typer.Option(None, "--geometry", help="YAML file of geometry overrides"),
       algorithm: Optional[str] = typer.Option(None, "--algorithm", help=f"default: first of {', '.join(RELIABLE)} available"),
       seed: int = typer.Option(0, "--seed"),
       tolerance: float = typer.Option(1e-6, "--tolerance", help="largest residual (joint units) accepted as a solution"),
       all_solutions: bool = typer.Option(False, "--all-solutions", help="every distinct real solution in the bounds"),
       as_json: bool = typer.Option(False, "--json")):
    """Forward kinematics: solved for a parallel mechanism, closed form for a serial arm."""
    m = _mechanism(mech, geometry)
    values = m.vector(parse_assignments(joints, "--joints"), m.joint_names, "--joints")
    if m.kind == "serial":
        pose = m.fk(values)
        _emit({"pose": dict(zip(m.pose_names, map(float, pose)))}, as_json, m.pose_units)
        return
    from . import fk_problem, solve
    if all_solutions:
        from .assembly import all_solutions as find_all, solutions_to_dict
        found = find_all(m, values, seed=seed)
        data = solutions_to_dict(found)
        if as_json:
            typer.echo(json.dumps(data))
        else:
            _console().print(f"{len(data['solutions'])} distinct solutions")
            for s in data["solutions"]:
                _console().print(s)
        return
    problem = fk_problem(m, values)
    name = algorithm or _default_algorithm()
    res = solve(problem, name, population=20, iterations=300, runs=1, seed=seed)
    x = res.x[0]
    residual = float(np.max(np.abs(problem.residuals(x))))
    if not residual <= tolerance:
        raise FkoptError(f"no pose within the bounds reproduces these joints: best residual {residual:.3g} "
                         f"(joint units) at {', '.join(f'{n}={v:.6g}' for n, v in zip(m.pose_names, x))}")
    _emit({"pose": dict(zip(m.pose_names, map(float, x))), "fitness": float(res.fitness[0]),
           "residual": residual, "algorithm": name}, as_json, m.pose_units)


def _emit(data: dict, as_json: bool, units) -> None:
    if as_json:
        typer.echo(json.dumps(data))
        return
    key = "joints" if "joints" in data else "pose"
    for (name, value), unit in zip(data[key].items(), units):
        typer.echo(f"{name:>8} = {value:.10g} {unit}")
    for name, value in data.items():
        if name != key:
            typer.echo(f"{name:>8}: {value:.6g}" if isinstance(value, float) else f"{name:>8}: {value}")


@app.command("export")
def export_cmd(results: Path = typer.Argument(..., help="results folder: one experiment or a root of them"),
               fmt: str = typer.Option("ioh", "--format", help="ioh: IOHprofiler data for IOHanalyzer"),
               out: Path = typer.Option(..., "--out", help="folder to write (outside RESULTS)")):
    """Export stored results for other tools (IOHanalyzer), without rerunning anything."""
    from .export import FORMATS, ioh_export
    if fmt not in FORMATS:
        raise FkoptError(f"--format: unknown format '{fmt}'; allowed: {', '.join(FORMATS)}")
    files = ioh_export(results, out)
    typer.echo(f"wrote {len(files) - 1} IOHprofiler index files (.json) and their .dat files to {out}")


@app.command()
def bench(quick: bool = typer.Option(False, "--quick", help="short measurement (~20 s)"),
          peers: bool = typer.Option(False, "--peers", help="also time NiaPy/MEALPY/... if installed"),
          out: Path = typer.Option(Path("bench"), "--out", help="folder for bench.csv and scaling.png")):
    """Measure fkopt's speed (and peers') on this machine."""
    from .bench import run as run_bench
    run_bench(quick=quick, peers=peers, out=out)


@app.command()
def reproduce(configs: Path = typer.Option(Path("configs"), "--configs", help="folder of experiment files"),
              out: Path = typer.Option(Path("results"), "--out", help="results root"),
              quiet: bool = typer.Option(False, "--quiet", "-q")):
    """Run every experiment under CONFIGS, rewrite OUT and its REPORT.md, TIMING.md, index.csv."""
    import shutil
    import time
    from rich.table import Table
    from .experiment.reports import write_experiment
    from .experiment.runner import run_experiment
    from .reproduce.report import write_report
    from .experiment.kinds import load_any, validate_any
    from .study.config import StudyConfig
    from .study.runner import run_study

    files = sorted(configs.rglob("*.yaml"))
    if not files:
        raise FkoptError(f"{configs}: no experiment files (*.yaml) found")
    from .experiment.assembly import AssemblyConfig, run_assembly, write_assembly
    loaded = [(f, load_any(f)) for f in files]     # experiments, studies and assembly-mode files (kind:)
    sizes = {}
    for f, c in loaded:
        try:
            sizes[f] = validate_any(c)
        except FkoptError as err:
            raise FkoptError(f"{f}: {err}") from None
    con = _console()
    done = []
    start = time.perf_counter()
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
    with Progress(TextColumn("{task.fields[name]}"), BarColumn(), MofNCompleteColumn(),
                  TextColumn("{task.description}"), TimeElapsedColumn(), console=con,
                  disable=quiet) as bar:
        overall = bar.add_task("", total=len(loaded), name="[bold]reproduce[/]")
        for f, c in loaded:
            task = bar.add_task("", total=sizes[f], name=f"  {c.paper}/{c.name}")
            update = lambda label, d, t: bar.update(task, completed=d, description=label)  # noqa: E731
            if isinstance(c, AssemblyConfig):
                mech, sols, wall = run_assembly(c)
                folder = write_assembly(c, mech, sols, wall, out, str(f))
                er = type("Done", (), {"wall_s": wall})
            elif isinstance(c, StudyConfig):
                er = run_study(c, out, source=str(f), progress=update)
                folder = er.folder
                # Task files exist for --resume; a finished reproduction keeps only its results.
                shutil.rmtree(folder / "tasks", ignore_errors=True)
            else:
                er = run_experiment(c, source=str(f), progress=update)
                folder = write_experiment(er, out)
            bar.remove_task(task)
            bar.advance(overall)
            done.append((f, folder, er.wall_s, len(list(folder.iterdir()))))
    paths = write_report(out)
    total = time.perf_counter() - start
    if not quiet:
        table = Table(title=f"reproduced {len(done)} experiments in {total:.1f} s")
        for col in ("config", "results", "files", "seconds"):
            table.add_column(col)
        for f, folder, wall, n in done:
            table.add_row(str(f), str(folder), str(n), f"{wall:.1f}")
        con.print(table)
        con.print("report: " + ", ".join(str(p) for p in paths))


@app.command()
def report(results: Path = typer.Argument(Path("results"), help="results root")):
    """Regenerate REPORT.md, TIMING.md and index.csv from stored results (no rerun)."""
    from .reproduce.report import write_report
    for p in write_report(results):
        typer.echo(str(p))


@app.command()
def check(results: Path = typer.Argument(Path("results"), help="results root"),
          subset: str = typer.Option("all", "--subset", help="all | ci"),
          experiment: Optional[list[str]] = typer.Option(None, "--experiment", "-e",
                                                         help="PAPER/NAME to check (repeatable)"),
          quiet: bool = typer.Option(False, "--quiet", "-q")):
    """Rerun stored experiments from their recorded config; fail if results drifted."""
    from .reproduce.check import check_experiment, select
    from .reproduce.store import Store
    if subset not in ("all", "ci"):
        raise FkoptError(f"--subset: '{subset}' unknown; allowed: all, ci")
    exps = select(Store(results), subset)
    if experiment:
        wanted = set(experiment)
        exps = [e for e in exps if f"{e.paper}/{e.name}" in wanted]
        missing = wanted - {f"{e.paper}/{e.name}" for e in exps}
        if missing:
            raise FkoptError(f"--experiment: no stored experiment {sorted(missing)[0]} under {results}")
    if not exps:
        raise FkoptError(f"{results}: no stored experiments (folders with meta.json) to check")
    failures = []
    for e in exps:
        bad = check_experiment(e)
        failures += bad
        if not quiet:
            typer.echo(f"{'ok  ' if not bad else 'FAIL'} {e.paper}/{e.name}")
    if failures:
        for m in failures[:20]:
            typer.echo(f"drift: {m}", err=True)
        raise FkoptError(f"{len(failures)} value(s) drifted in {len({m.experiment for m in failures})} "
                         f"experiment(s); first: {failures[0]}")
    if not quiet:
        typer.echo(f"{len(exps)} experiments match their stored results")


def main() -> None:
    interrupted = ("fkopt: interrupted (no results folder was left half-written; the finished tasks of a "
                   "study are kept: fkopt study CONFIG --resume continues)")
    try:
        code = app(standalone_mode=False)
    except FkoptError as err:
        print(f"fkopt: error: {err}", file=sys.stderr)
        sys.exit(2)
    except KeyboardInterrupt:
        print(interrupted, file=sys.stderr)
        sys.exit(130)
    except Exception as err:  # click's usage errors (typer vendors click): no traceback either
        kind = type(err).__name__
        if kind == "Exit":
            sys.exit(getattr(err, "exit_code", 0))
        if kind == "Abort":
            print("fkopt: interrupted", file=sys.stderr)
            sys.exit(130)
        if callable(getattr(err, "format_message", None)):
            print(f"fkopt: error: {err.format_message()} (see fkopt --help)", file=sys.stderr)
            sys.exit(2)
        raise
    if code == 130:   # typer (>= 0.12) turns Ctrl-C into a returned 130 when not standalone
        print(interrupted, file=sys.stderr)
        sys.exit(130)
    if isinstance(code, int) and code:
        sys.exit(code)

if __name__ == "__main__":
    main()
