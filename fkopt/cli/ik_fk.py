"""``fkopt ik`` and ``fkopt fk``: one pose or one set of joints, solved by the library
(closed form, :func:`fkopt.inverse`, :func:`fkopt.forward`, all solutions, or a registered
algorithm), the answer printed as lines or one JSON object; exit 1 when it is not a solution
within the tolerances, 2 for bad input.

``fkopt.forward``, ``fkopt.inverse`` and the assembly-mode search are loaded with the registry
anyway; the solvers by algorithm (:mod:`fkopt.kinematics.by_algorithm`, ~2 ms of imports) are
imported at the top too (docs/design.md, "Start-up")."""
from __future__ import annotations

import sys
from pathlib import Path
from typing import Optional

import numpy as np
import typer

from fkopt.cli.arguments import arm_target, mechanism_from_options, parse_assignments, rotation_counts
from fkopt.cli.entry_point import app, console
from fkopt.errors import FkoptError
from fkopt.files import strict_json
from fkopt.kinematics import inverse as inverse_solutions      # inverse(..., solutions="all")
from fkopt.kinematics.assembly_modes import all_solutions as find_all, solutions_to_dict
from fkopt.kinematics.by_algorithm import forward_by, inverse_by
from fkopt.kinematics.solvers import forward, inverse
from fkopt.numerics.rotations import zyz_angles


def _not_solved(message: str, data: dict, as_json: bool, units) -> None:
    """A computed answer that is not a solution within tolerance: the best answer on stdout
    (JSON with ``"solved": false``, or nothing), one line on stderr, exit status 1."""
    if as_json:
        typer.echo(strict_json(data))
    print(f"fkopt: error: {message}", file=sys.stderr)
    raise typer.Exit(1)



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
    m = mechanism_from_options(mech, geometry)
    given = parse_assignments(pose, "--pose")
    serial_frame = m.kind != "parallel" and tuple(m.pose_names[3:]) == ("alpha", "beta", "gamma")
    rotation = rotation_counts(mask)
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
        if serial_frame:       # the swarms' objective takes Z-Y-Z angles: the target's, exactly as given
            R = target[:3, :3]
            values = np.concatenate([target[:3, 3], np.degrees(zyz_angles(tuple(tuple(r) for r in R)))])
        out = inverse_by(m, values, algorithm, tol=(position_tol, orientation_tol), seed=seed).as_dict()
        out.pop("restarts")
        out["objective"] = "geodesic"
        out["algorithm"] = algorithm
        perr, rerr = out["position_error"], out["rotation_error_rad"]
    else:
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
    given = (position_tol, orientation_tol) != (1e-6, 1e-6)          # the command's defaults
    locked = None if fixed is None else parse_assignments(fixed, "--fixed")
    extra = {k: v for k, v in (("fixed", locked), ("spread", spread)) if v is not None}
    r = inverse_solutions(m, values, solutions="all", tol=(position_tol, orientation_tol) if given else None,
                          mask=mask, seed=seed, **extra)
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
    m = mechanism_from_options(mech, geometry)
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
        # One search per process: the homotopy's compiled tracker and start system (~1 s to load)
        # cost more than the restart search takes (~0.2 s), so a one-shot call runs the restarts.
        found = find_all(m, values, seed=seed, method="restarts")
        data = solutions_to_dict(found)
        if as_json:
            typer.echo(strict_json(data))
        else:
            console().print(f"{len(data['solutions'])} distinct solutions")
            for s in data["solutions"]:
                console().print(s)
        return
    if algorithm:
        r = forward_by(m, values, algorithm, tol=tolerance, seed=seed)
        out = r.as_dict()
        out.pop("stage")
        out["algorithm"] = algorithm
        x = r.pose
    else:
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
