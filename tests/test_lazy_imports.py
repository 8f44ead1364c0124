"""Mechanism presets build their pydantic geometry model only when it is read, and overrides are
still validated (the process time of fk/ik is measured in ``fkopt bench --section kinematics``).
Every command line goes through typer: the hand-written parser that skipped it for fk/ik/list
saved ~12 ms of a ~255 ms process (5 %, measured alternating 12 runs each) and was removed."""
from __future__ import annotations

import subprocess
import sys

import pytest

import fkopt
from fkopt import registry

JOINTS = "l1=0.75,l2=0.78,l3=0.8,l4=0.9,l5=0.87,l6=0.85"


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


def test_lazy_package_attributes():
    assert fkopt.solve.__module__ == "fkopt.solve" and fkopt.forward.__module__ == "fkopt.kinematics.solvers"
    assert isinstance(fkopt.__version__, str)
    with pytest.raises(AttributeError):
        fkopt.no_such_name
