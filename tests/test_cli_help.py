"""The command line explains itself (issue 23): --version, bare `fkopt`, option descriptions,
units and residuals in the answers, a default --out outside the tracked results/, `fkopt schema`."""
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import typer.main
import yaml

from fkopt import cli
from fkopt.cli.entry_point import DEFAULT_OUT
from fkopt.cli.listing import unit_groups
from fkopt.tools.bench import sections as bench

ROOT = Path(__file__).resolve().parent.parent
COMMANDS = typer.main.get_command(cli.app).commands


def fkopt_process(*args, env=None):
    """``python -m fkopt.cli ARGS`` in a fresh interpreter (what a start-up reads: the environment)."""
    env = dict(os.environ, **(env or {}), COLUMNS="200", PYTHONPATH=os.pathsep.join(
        filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
    return subprocess.run([sys.executable, "-m", "fkopt.cli", *args], capture_output=True, text=True,
                          env=env, timeout=300)


@pytest.fixture
def fkopt(fkopt_run):
    """``fkopt ARGS`` in this process (conftest's ``fkopt_run``): these tests check the text and exit
    status, not the start-up (test_version keeps a process)."""
    return fkopt_run


def test_version():
    import fkopt as package
    proc = fkopt_process("--version", env={"FKOPT_NUMERICS": "auto"})
    from importlib.metadata import version
    assert proc.returncode == 0, proc.stderr
    # the version, the numerics path a default call takes here and the compiler's version (issue 38)
    assert proc.stdout.strip() == (f"fkopt {package.__version__}; numerics: compiled (numba {version('numba')}, "
                                   f"llvmlite {version('llvmlite')})")
    proc = fkopt_process("--version", env={"FKOPT_NUMERICS": "numpy"})
    assert proc.stdout.strip() == f"fkopt {package.__version__}; numerics: numpy (FKOPT_NUMERICS=numpy)"


def test_python_dash_m_runs_the_console_scripts_main():
    """`python -m fkopt.cli` (the Makefile's and the subprocess tests' way in) is the console script's
    main; imported here so the fast tier reaches fkopt/cli/__main__.py in-process too."""
    import fkopt.cli.__main__ as dash_m
    from fkopt.cli.entry_point import main
    assert dash_m.main is main


def test_bare_fkopt_prints_help_and_succeeds(fkopt):
    proc = fkopt()
    assert proc.returncode == 0, proc.stderr
    assert "Usage" in proc.stdout and "run" in proc.stdout and proc.stderr == ""


@pytest.mark.parametrize("command", [None, *COMMANDS])
def test_help_tags_no_flag_with_a_type(command, fkopt):
    proc = fkopt(*([command] if command else []), "--help")
    assert proc.returncode == 0
    assert "<bool>" not in proc.stdout
    if command == "fk":
        assert "<float>" in proc.stdout          # options that take a value keep their type


@pytest.mark.parametrize("command", list(COMMANDS))
def test_every_option_and_argument_is_described(command):
    undocumented = [p.name for p in COMMANDS[command].params if not getattr(p, "help", None)]
    assert not undocumented, f"fkopt {command}: {undocumented} have no help text"


def test_bench_help_lists_every_section(fkopt):
    text = " ".join(fkopt("bench", "--help").stdout.split())
    for section in bench.SECTIONS:
        assert section in text
    assert "cases (N cases x 30 runs" in text


def test_study_help_explains_instead_of_pointing_at_a_module(fkopt):
    text = " ".join(fkopt("study", "--help").stdout.split())
    assert "see fkopt.kinds.study" not in text
    assert "kind: study" in text and "tracking" in text and "docs/config-reference.md" in text


def test_ik_prints_its_residual_with_units(fkopt):
    parallel = fkopt("ik", "3-rps", "--pose", "alpha=9,beta=13,z=622")
    assert parallel.returncode == 0 and "residual: 0 (closed form" in parallel.stdout
    serial = fkopt("ik", "7dof-arm", "--pose", "x=-247.4874,y=1009.6194,z=500,alpha=-135,beta=90,gamma=-90")
    assert serial.returncode == 0
    line = next(l for l in serial.stdout.splitlines() if l.startswith("position_error:"))
    assert line.split()[2] == "mm" and "residual" in line
    assert any(l.startswith("rotation_error_rad:") and l.split()[2] == "rad" for l in serial.stdout.splitlines())


def test_fk_says_which_stage_found_the_pose(fkopt):
    proc = fkopt("fk", "3-rps", "--joints", "d1=598.8458,d2=671.9171,d3=629.1616", "--json")
    out = json.loads(proc.stdout)
    assert "stage" not in out and out["found_by"] == "local newton"
    text = fkopt("fk", "3-rps", "--joints", "d1=598.8458,d2=671.9171,d3=629.1616").stdout
    assert "found_by: local newton" in text and "joint units" in text


def test_list_fits_80_columns(fkopt):
    for args in (["list"], ["list", "--long"]):
        proc = fkopt(*args, columns=80)
        assert proc.returncode == 0
        wide = [line for line in proc.stdout.splitlines() if len(line) > 80]
        assert not wide, wide[:2]
        assert "3-rpupc-ups" in proc.stdout
    assert "q1..q7 [deg]" in proc.stdout                      # --long: the units of each name


def test_unit_groups():
    assert unit_groups(["x", "y", "z", "alpha"], ["m", "m", "m", "deg"]) == "x, y, z [m]\nalpha [deg]"
    assert unit_groups(["q1", "q2", "q3"], ["deg"] * 3) == "q1..q3 [deg]"
    assert unit_groups(["q1", "q3", "q4"], ["deg"] * 3) == "q1, q3, q4 [deg]"


def test_run_writes_under_fkopt_results_by_default(tmp_path, fkopt):
    config = {"name": "tiny", "mechanism": {"name": "3-rps"},
              "cases": [{"pose": {"alpha": 9, "beta": 13, "z": 622}}],
              "algorithms": [{"name": "gabc"}], "population": 4, "iterations": 3, "runs": 2}
    (tmp_path / "tiny.yaml").write_text("# yaml-language-server: $schema=docs/schema/experiment.json\n"
                                        + yaml.safe_dump(config))
    proc = fkopt("run", "tiny.yaml", "--quiet", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "fkopt-results" / "experiments" / "tiny" / "summary.csv").is_file()
    assert not (tmp_path / "results").exists()
    assert DEFAULT_OUT == Path("fkopt-results")
    assert "/fkopt-results/" in (ROOT / ".gitignore").read_text().splitlines()


def test_schema_command_prints_the_committed_schemas(fkopt):
    for args, kind in (((), "experiment"), (("study",), "study"), (("assembly",), "assembly"), (("suite",), "suite")):
        proc = fkopt("schema", *args)
        assert proc.returncode == 0
        assert proc.stdout == (ROOT / "docs" / "schema" / f"{kind}.json").read_text(encoding="utf-8")
    bad = fkopt("schema", "nope")
    assert bad.returncode == 2 and bad.stderr.strip() == \
        "fkopt: error: schema: unknown kind 'nope'; allowed: experiment, study, assembly, suite"


def test_help_paragraphs_are_wrapped_by_the_terminal_not_the_source(fkopt):
    text = fkopt("fk", "--help", columns=200).stdout
    assert "reproduces the joints within --tolerance (the best residual is reported)" in text
