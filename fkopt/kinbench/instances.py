"""Geometry instances of the parallel mechanisms: ``instances: K`` on a suite problem.

One build of a mechanism lets a solver be tuned to it; K seeded geometries around the paper's
make a result about the mechanism class (as COCO's instances of a function). A suite problem

    - {name: mao2017-3rps, problem_class: parallel-fk-3dof, instances: 10,
       mechanism: {name: 3-rps, geometry: {ra: 274, rb: 158}}}

stands for the problems ``mao2017-3rps-i1`` ... ``mao2017-3rps-i10`` (the problem as written, the
paper's geometry, is not among them: list it as well to keep it). The suffix ``-ik`` rather than
``#k``: a problem's name is also a folder (its pose sets) and a label in the HTML board, where
``#`` is not a safe character. Instance k's geometry is the
problem's geometry (over the mechanism's defaults) with each parameter of :data:`SPREADS` drawn
from the stream ``PCG64(SeedSequence([suite seed, crc32(problem name), crc32("instance"), k]))``:

* ``("scale", s)``: the value times U(1 - s, 1 + s) (radii, offsets, probe lengths: +-20 %);
* ``("shift", s)``: the value plus U(-s, s) (angles in degrees: +-10 deg);
* ``("points", s)``: each coordinate of a list of joint points plus U(-s, s) x the largest
  distance of a point from the origin (Dietmaier's 6-6 joints: +-5 %).

Rounded to 6 significant digits (the suite's files show what runs). Each instance carries its
workspace box: the mechanism's default bounds for that geometry (a box around the paper's
workspace; for ``6-sps`` the geometry-dependent box of :func:`fkopt.mechanisms.sps6.general_bounds`),
written into the instance's ``mechanism.bounds`` so the pose sets' manifest records it.

A draw is kept only if the instance is **non-degenerate**: the inverse map is finite at
:data:`CHECK_POSES` uniform poses of the box and the condition number of the residual Jacobian at
the box centre is below :data:`MAX_CENTRE_KAPPA` (a geometry whose home pose is singular is
redrawn, from the same stream, at most :data:`ATTEMPTS` times; then the suite is refused).
"""
from __future__ import annotations

import zlib
from types import SimpleNamespace

import numpy as np

from fkopt.errors import FkoptError
from fkopt import registry
from fkopt.kinbench.posesets import condition_numbers, problem_mechanism
from fkopt.run.config_base import MechanismSpec

#: Parameters drawn per mechanism (module docstring); a mechanism not listed takes no instances.
SPREADS: dict[str, dict[str, tuple[str, float]]] = {
    "3-rps": {"ra": ("scale", 0.2), "rb": ("scale", 0.2)},
    "3-ppr": {"r_F": ("scale", 0.2), "phi1": ("shift", 10.0), "phi2": ("shift", 10.0), "phi3": ("shift", 10.0),
              "D1x0": ("scale", 0.2), "D2x0": ("scale", 0.2)},
    "3-rpupc-ups": {"R": ("scale", 0.2), "c": ("scale", 0.2)},
    "6-sps-cmm": {"Rb": ("scale", 0.2), "Rp": ("scale", 0.2), "tb": ("shift", 10.0), "tp": ("shift", 10.0),
                  "ls": ("scale", 0.2)},
    "6-sps": {"base": ("points", 0.05), "platform": ("points", 0.05)},
}
CHECK_POSES = 2000
MAX_CENTRE_KAPPA = 1e6
ATTEMPTS = 20
MAX_INSTANCES = 100
#: Most geometry instances of one suite, all problems' ``instances`` added up, checked before any
#: is drawn: each takes ~0.3 s (up to ATTEMPTS draws, a degeneracy check of CHECK_POSES poses), so a
#: small suite file cannot keep fkopt busy for minutes before a cheap error (issue 42). v3 has 50.
MAX_SUITE_INSTANCES = 100


def instance_rng(seed: int, problem: str, k: int) -> np.random.Generator:
    key = [int(seed), zlib.crc32(problem.encode()), zlib.crc32(b"instance"), int(k)]
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(key)))


def _sig(v: float) -> float:
    return float(f"{float(v):.6g}")


def draw_geometry(mechanism: str, geometry: dict, rng: np.random.Generator) -> dict:
    """One draw of the parameters of :data:`SPREADS` around ``geometry`` (mechanism defaults filled in)."""
    spreads = SPREADS[mechanism]
    cls = registry.mechanism_class(mechanism)
    base = {**cls.Geometry().model_dump(mode="json"), **geometry}
    out = dict(geometry)
    for key, (kind, s) in spreads.items():
        value = base[key]
        if kind == "scale":
            out[key] = _sig(value * (1.0 - s + 2.0 * s * rng.random()))
        elif kind == "shift":
            out[key] = _sig(value + s * (2.0 * rng.random() - 1.0))
        else:
            pts = np.asarray(value, dtype=float)
            size = float(np.linalg.norm(pts, axis=1).max())
            moved = pts + s * size * (2.0 * rng.random(pts.shape) - 1.0)
            out[key] = [[_sig(v) for v in row] for row in moved]
    return out


def degeneracy(spec, rng: np.random.Generator) -> str | None:
    """Why the instance ``spec`` (a MechanismSpec with bounds) is degenerate, or None (module docstring)."""
    problem = SimpleNamespace(mechanism=spec, objective=None)
    try:
        mech, _ = problem_mechanism(problem)
    except FkoptError as err:
        return str(err)
    lo, hi = mech.bounds[:, 0], mech.bounds[:, 1]
    poses = lo + rng.random((CHECK_POSES, len(lo))) * (hi - lo)
    if not np.all(np.isfinite(mech.ik(poses))):
        return "its inverse map is not finite everywhere in the box"
    kappa = float(condition_numbers(problem, None, ((lo + hi) / 2)[None])[0])
    if not kappa < MAX_CENTRE_KAPPA:
        return f"its residual Jacobian at the box centre has condition number {kappa:.3g}"
    return None


def expand(problem: dict, seed: int, where: str) -> list[dict]:
    """The K instance problems (dicts of SuiteProblem fields) of a problem with ``instances: K``."""
    k_total = problem["instances"]
    if len(f"{problem['name']}-i{k_total}") > 64:
        raise FkoptError(f"{where}.name: '{problem['name']}' is too long for its instance names (64 characters)")
    name = problem["mechanism"]["name"]
    if name not in SPREADS:
        raise FkoptError(f"{where}.instances: mechanism '{name}' has no geometry instances (allowed for: "
                         f"{', '.join(SPREADS)})")
    if problem["mechanism"].get("bounds"):
        raise FkoptError(f"{where}.instances: each instance has its own workspace box; drop mechanism.bounds")
    out = []
    for k in range(1, k_total + 1):
        rng = instance_rng(seed, problem["name"], k)
        why = None
        for _ in range(ATTEMPTS):
            geometry = draw_geometry(name, problem["mechanism"].get("geometry", {}), rng)
            spec = MechanismSpec(name=name, geometry=geometry)
            try:
                mech, _ = problem_mechanism(SimpleNamespace(mechanism=spec, objective=problem.get("objective")))
            except FkoptError as err:
                why = str(err)
                continue
            box = {n: (_sig(lo), _sig(hi)) for n, (lo, hi) in zip(mech.unknown_names, mech.bounds)}
            spec = MechanismSpec(name=name, geometry=geometry, bounds=box)
            why = degeneracy(spec, rng)
            if why is None:
                break
        else:
            raise FkoptError(f"{where}.instances: no non-degenerate geometry for instance {k} in {ATTEMPTS} draws "
                             f"(last: {why})")
        out.append({**{f: v for f, v in problem.items() if f != "instances"}, "name": f"{problem['name']}-i{k}",
                    "mechanism": spec.model_dump(mode="json")})
    return out
