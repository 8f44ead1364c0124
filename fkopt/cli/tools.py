"""The commands of fkopt's tools: ``fkopt export`` (stored results as IOHprofiler files) and
``fkopt bench`` (fkopt's speed on this machine, peers' beside it).

:mod:`fkopt.tools.export` and :mod:`fkopt.tools.bench` are imported inside the commands: they pull
pandas, matplotlib and the solvers, which the light commands never use (docs/design.md,
"Start-up")."""
from __future__ import annotations

from pathlib import Path

import typer

from fkopt.cli.entry_point import app
from fkopt.errors import FkoptError
from fkopt.files import output_folder


@app.command("export")
def export_cmd(results: Path = typer.Argument(..., help="results folder: one experiment or a root of them"),
               fmt: str = typer.Option("ioh", "--format", help="ioh: IOHprofiler data for IOHanalyzer"),
               out: Path = typer.Option(..., "--out", help="folder to write (outside RESULTS)")):
    """Export stored results for other tools (IOHanalyzer), without rerunning anything."""
    from fkopt.tools.export import FORMATS, ioh_export  # lazy: the export pulls pandas and kinbench (start-up)
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
    from fkopt.tools.bench.sections import SECTIONS, run as run_bench  # lazy: start-up (every section)
    bad = [s for s in section if s not in SECTIONS]
    if bad:
        raise typer.BadParameter(f"unknown section {bad[0]!r}; allowed: {', '.join(SECTIONS)}",
                                 param_hint="--section")
    output_folder(out)                 # a writable folder, not a file: before measuring anything
    run_bench(quick=quick, peers=peers or "peers" in section, out=out, sections=section or None)
