"""fk/ik/list load only what they need: no pydantic on a preset without geometry overrides
(issue 12; the process time itself is measured in ``fkopt bench --section kinematics``)."""
from __future__ import annotations

import subprocess
import sys

import pytest

import fkopt
from fkopt import cli, registry

JOINTS = "l1=0.75,l2=0.78,l3=0.8,l4=0.9,l5=0.87,l6=0.85"


def _imported(*args):
    proc = subprocess.run([sys.executable, "-X", "importtime", "-m", "fkopt.cli", *args],
                          capture_output=True, text=True, timeout=300)
    return proc, {line.split("|")[-1].strip() for line in proc.stderr.splitlines() if "|" in line}


@pytest.mark.parametrize("args", [["fk", "6-sps-cmm", "--joints", JOINTS],
                                  ["fk", "6-sps-cmm", f"--joints={JOINTS}", "--seed", "3", "--json"],
                                  ["ik", "7dof-arm", "--pose", "x=300,y=200,z=600,alpha=10,beta=60,gamma=20"]])
def test_fk_ik_on_a_preset_import_no_pydantic(args):
    proc, imported = _imported(*args)
    assert proc.returncode in (0, 1), proc.stderr[-500:]
    assert not {m for m in imported if m.split(".")[0] == "pydantic"}


def test_geometry_overrides_are_still_validated(tmp_path):
    bad = tmp_path / "g.yaml"
    bad.write_text("Rb: -1\n")
    proc = subprocess.run([sys.executable, "-m", "fkopt.cli", "fk", "6-sps-cmm", "--joints", JOINTS,
                           "--geometry", str(bad)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1
    assert "6-sps-cmm geometry.Rb" in proc.stderr


def _with_defaults(present: bool):
    return [n for n in registry.MECHANISMS if (registry.mechanism_class(n).geometry_defaults is not None) == present]


@pytest.mark.parametrize("name", _with_defaults(False))
def test_mechanisms_without_pydantic_free_defaults_build_their_model_at_once(name):
    """No ``geometry_defaults``: the mechanism validates its pydantic Geometry model when it is
    made (only the presets fk/ik use on the fast path carry pydantic-free defaults)."""
    m = registry.mechanism_class(name)()
    assert "geometry" in m.__dict__ and m.geometry_values() is m.geometry


@pytest.mark.parametrize("name", _with_defaults(True))
def test_pydantic_free_defaults_equal_the_models_defaults(name):
    cls = registry.mechanism_class(name)
    assert cls.Geometry().model_dump() == cls.geometry_defaults
    m = cls()
    assert "geometry" not in m.__dict__                 # not built until read
    values = m.geometry_values().__dict__
    assert m.geometry.model_dump() == values          # built on first access, same values


@pytest.mark.parametrize("argv", [["fk", "6-sps-cmm", "--help"], ["fk", "6-sps-cmm", "--seed", "-1", "--joints", "a=1"],
                                  ["fk", "6-sps-cmm", "--joints", "a=1", "--joints", "b=2"],
                                  ["fk", "6-sps-cmm", "--nope", "1", "--joints", "a=1"],
                                  ["fk", "6-sps-cmm"], ["fk", "--joints", "a=1"], ["fk", "a", "b", "--joints", "x=1"],
                                  ["fk", "6-sps-cmm", "--joints", "a=1", "--tolerance", "1e-3x"],
                                  ["fk", "6-sps-cmm", "--joints"], ["run", "x.yaml"], []])
def test_direct_parsing_leaves_everything_unusual_to_typer(argv):
    assert cli._direct(argv) is None


def test_direct_parsing_matches_the_signature():
    func, kw = cli._direct(["fk", "--tolerance=1e-6", "6-sps-cmm", "--joints", "a=1", "--all-solutions"])
    assert func is cli.fk
    assert kw == {"mech": "6-sps-cmm", "joints": "a=1", "geometry": None, "algorithm": None, "seed": 0,
                  "tolerance": 1e-6, "all_solutions": True, "as_json": False}
    func, kw = cli._direct(["list"])
    assert func is cli.list_cmd and kw == {"mech": None, "geometry": None, "as_json": False}


def test_lazy_package_attributes():
    assert fkopt.solve.__module__ == "fkopt.solve" and fkopt.forward.__module__ == "fkopt.kinematics"
    assert isinstance(fkopt.__version__, str)
    with pytest.raises(AttributeError):
        fkopt.no_such_name
