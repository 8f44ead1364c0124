"""What the commands parse from their options: ``name=value`` lists (``--pose``, ``--joints``,
``--start``, ``--fixed``), a mechanism with its ``--geometry`` file, and a serial arm's target
frame from ``--pose`` (:func:`arm_target`). Every refusal is one line naming the option."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Optional

import numpy as np

import fkopt
from fkopt.errors import FkoptError
from fkopt.files import did_you_mean, load_mapping
from fkopt.numerics import rotations
from fkopt.registry import mechanism_class, resolve_files


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
    """The mapping of a --geometry YAML file ({} without one)."""
    if path is None:
        return {}
    return load_mapping(path, "geometry keys")


def mechanism_from_options(name: str, geometry: Optional[Path]):
    """Mechanism ``name`` with the overrides of a --geometry YAML file (its relative file paths,
    e.g. a URDF's, taken from the YAML's folder), or, for ``urdf``, a .urdf file itself."""
    if geometry is not None and geometry.suffix.lower() == ".urdf":
        try:
            return fkopt.mechanism(name, file=str(geometry))
        except FkoptError as err:
            if "name geometry." not in str(err):
                raise
            raise FkoptError(f"{err}: with a branching tree give --geometry a YAML file with "
                             f"'file: {geometry.name}', 'base:' and 'tip:'") from None
    values = load_geometry(geometry)
    if geometry is not None:
        values = resolve_files(mechanism_class(name), values, geometry.parent)
    return fkopt.mechanism(name, **values)


#: The rotations ``fkopt ik`` takes for a serial arm's target, by name (degrees; a quaternion unitless).
ARM_ROTATIONS = {
    ("alpha", "beta", "gamma"): "Z-Y-Z Euler angles, R = Rz(alpha) Ry(beta) Rz(gamma) (fkopt fk prints these)",
    ("roll", "pitch", "yaw"): "R = Rz(yaw) Ry(pitch) Rx(roll), as URDF composes rpy",
    ("qw", "qx", "qy", "qz"): "a unit quaternion (normalised)",
}


def rotation_counts(mask: Optional[str]) -> bool:
    """Whether the orientation is part of the task (--mask names rx, ry or rz, or no --mask)."""
    return mask is None or any(part.strip() in ("rx", "ry", "rz") for part in mask.split(","))


def arm_target(m, given: dict[str, float], rotation: bool) -> np.ndarray:
    """The tip frame (4, 4) of a serial arm's ``--pose``: x, y, z and one rotation of
    :data:`ARM_ROTATIONS` by name (none when ``rotation`` is False: the identity, which no
    error then counts). Every refusal is one line naming what is allowed."""
    names = set(given)
    allowed = ["x", "y", "z", *(n for group in ARM_ROTATIONS for n in group)]
    unknown = sorted(names - set(allowed))
    if unknown:
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
