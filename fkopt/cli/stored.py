"""The commands on stored results: ``fkopt reproduce`` (every paper's experiments rerun into a
folder and compared with the stored ones), ``fkopt report`` (REPORT.md, TIMING.md, index.csv
from stored results), ``fkopt pages`` (kinbench's pages and figures from its stored tables) and
``fkopt check`` (rerun stored results; exit 1 on drift).

:mod:`fkopt.reproduce`, :mod:`fkopt.kinbench` and rich are imported inside the commands: they pull
the engine, pandas and matplotlib, which the light commands never use (docs/design.md,
"Start-up")."""
from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Optional

import typer

from fkopt.cli.display import Heartbeat
from fkopt.cli.entry_point import DEFAULT_OUT, INTERRUPTED, app, console
from fkopt.errors import FkoptError


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
    from fkopt.reproduce.changes import agreement, snapshot  # lazy: reproduce pulls pandas and matplotlib (start-up)
    from fkopt.reproduce.report import write_report  # lazy: as above
    from fkopt.reproduce.run import default_jobs, plan, run_all  # lazy: as above
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
    from rich.table import Table

    if jobs is not None and jobs < 1:
        raise FkoptError(f"--jobs: must be at least 1, got {jobs}")
    planned = plan(configs, out)        # every file validated, every output checked: nothing run yet
    kept = tempfile.TemporaryDirectory(prefix="fkopt-reproduce-")   # the old files, to judge what moved
    in_place = out.resolve() == stored.resolve()
    # what the stored tree held, for CHANGES.md and the closing line: in place, the whole tree;
    # into a folder of its own, the stored results of the configs rerun (nothing else is compared)
    before = snapshot(stored, keep=Path(kept.name),
                      only=None if in_place else {"/".join(p.config.folder_parts) for p in planned})
    con = console()
    INTERRUPTED["hint"] = ("the configs finished so far are written; fkopt reproduce"
                           + ("" if out == DEFAULT_OUT / "reproduce" else f" --out {out}") + " starts again")
    start = time.perf_counter()
    heart = Heartbeat(con, quiet=quiet)
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
def report(results: Path = typer.Argument(Path("results"), help="results root"),
           snapshot_to: Optional[Path] = typer.Option(None, "--snapshot-to", help="only record the tree's "
                                                      "state in FILE (before a rerun such as make bench-suite)"),
           changes_since: Optional[Path] = typer.Option(None, "--changes-since", help="also write CHANGES.md: "
                                                        "what moved since the state recorded in FILE")):
    """Regenerate REPORT.md, TIMING.md and index.csv from stored results (no rerun)."""
    from fkopt.reproduce.changes import load_snapshot, save_snapshot, snapshot  # lazy: start-up (pandas)
    from fkopt.reproduce.report import write_report  # lazy: as above
    from fkopt.reproduce.store import Store  # lazy: as above
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
    from fkopt.kinbench.pages import regenerate, suite_folders  # lazy: kinbench pulls pandas and matplotlib (start-up)
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
    from fkopt.reproduce.check import check_experiment, select, stored_tier  # lazy: start-up (pandas)
    from fkopt.reproduce.store import locate  # lazy: as above
    if tier not in ("auto", "exact", "blas", "any"):
        raise FkoptError(f"--tier: '{tier}' unknown; allowed: auto, exact, blas, any")
    if tolerant and tier not in ("auto", "blas"):
        raise FkoptError(f"--tolerant is --tier blas; it cannot be combined with --tier {tier}")
    forced = "blas" if tolerant else (None if tier == "auto" else tier)
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
