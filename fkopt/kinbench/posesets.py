"""Frozen, versioned pose sets (kinbench v1): generated once from a seed, stored with SHA-256.

A pose set is a list of points in the space of a problem's unknowns (the pose of a parallel
mechanism, the joints of a serial arm), as in a study (:mod:`fkopt.kinds.study.poses`); what a solver
must reproduce follows from it (joints = ik(pose), or pose = fk(joints)). Sets of v1, each
drawn from its own stream ``PCG64(SeedSequence([seed, crc32(problem), crc32(set)]))``:

* ``uniform`` -- uniform in the box of the unknowns (the mechanism's workspace bounds);
* ``near-singular`` -- :data:`CANDIDATES` uniform candidates, ranked by the condition number
  kappa(J) = sigma_max / sigma_min of the residual Jacobian dr/dx of the problem at the true
  solution (for FK: d ik / d pose; for IK: d pose-error / d joints, in the problem's own units
  -- mm/deg or m/deg); a candidate is near-singular when kappa is above the bound
  :data:`SINGULAR_QUANTILE` (the 95th percentile of kappa over the candidates, recorded in the
  manifest); the set is the first such candidates in drawing order;
* ``boundary`` -- a uniform point with one coordinate (chosen uniformly) moved to within
  :data:`BOUNDARY_SHARE` of its range from one of its two bounds (chosen uniformly): the
  boundary of the box of the unknowns (the joint limits of an arm, the pose box of a platform);
* ``printed`` -- the poses printed in the papers (:data:`PRINTED`), in the unknowns' space.

Files: ``<folder>/<problem>/<set>.csv`` (one column per unknown, ``%.17g``: exact doubles) and
``<folder>/manifest.json``: version, seed, the generator's constants, per problem its mechanism
spec and per set the file's SHA-256, its number of poses and (near-singular) the bound.
:func:`load_pose_sets` verifies every checksum and that each problem's mechanism spec is the one
its sets were generated for; any mismatch is one error line naming the file. ``python -m
fkopt.kinbench.freeze pose-sets SUITE.yaml`` (re)writes a set folder; a new version is a new folder.
"""
from __future__ import annotations

import hashlib
import io
import json
import zlib
from pathlib import Path

import numpy as np

from fkopt.errors import FkoptError
from fkopt.run.config_base import files_folder, RunConfig
from fkopt.files import check_csv_shape, parse_json, read_input, short_token
from fkopt.kinbench.measures import characteristic_length, unit_free_sigma_min
from fkopt.kinbench.releases import check_release
from fkopt.mechanisms.urdf import URDFArm
from fkopt.run.solving import build_mechanism, make_problem

VERSION = "kinbench-v1"
#: Poses per generated set.
POSES = 20
CANDIDATES = 4000
SINGULAR_QUANTILE = 0.95
BOUNDARY_SHARE = 0.02
MANIFEST = "manifest.json"
#: The papers' printed poses, in the unknowns' space, by problem name (see the configs/ folders).
PRINTED: dict[str, list[dict[str, float]]] = {
    "mao2017-3rps": [{"alpha": 9, "beta": 13, "z": 622}, {"alpha": -13, "beta": -19, "z": 574},
                     {"alpha": -17, "beta": 8, "z": 436}, {"alpha": 18, "beta": 11, "z": 695},
                     {"alpha": 4, "beta": -7, "z": 509}],
    "liu2008-6sps": [{"x": 0.039860473384495845, "y": 0.09593004555681638, "z": 0.9252345609285073,
                      "alpha": -12.697325274301523, "beta": 6.40309494118661, "gamma": 15.133205922920425}],
    "chang2024-3rpupc": [{"alpha": 25, "beta": 34, "gamma": 23, "z": 360}],
    "wu2015-3ppr": [{"x": 20, "y": 30, "theta": 15}, {"x": 10, "y": 15, "theta": 5},
                    {"x": 10, "y": 20, "theta": 10}, {"x": 15, "y": 15, "theta": 10},
                    {"x": 15, "y": 20, "theta": 15}, {"x": 20, "y": 15, "theta": 10}],
    "wang2020-7dof": [{"q1": 45, "q2": 0, "q3": 45, "q4": 0, "q5": 45, "q6": 0, "q7": 0}],
}


def set_rng(seed: int, problem: str, name: str) -> np.random.Generator:
    key = [int(seed), zlib.crc32(problem.encode()), zlib.crc32(name.encode())]
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(key)))


def problem_mechanism(problem, folder: Path | None = None):
    """The mechanism of a suite problem (the experiment layer's builder) and the RunConfig it
    was built from (its objective is what :func:`fkopt.kinds.experiment.runner.make_problem` reads; the
    one algorithm entry only satisfies the schema)."""
    cfg = RunConfig(name="pose-set", mechanism=problem.mechanism, objective=problem.objective,
                    algorithms=[{"name": "lm"}])
    return build_mechanism(cfg, folder), cfg


def targets_of(mech, points: np.ndarray) -> np.ndarray:
    """What a solver must reproduce for each point: ik(pose) or fk(joints)."""
    return mech.fk(points) if mech.kind == "serial" else mech.ik(points)


def condition_numbers(problem, folder: Path | None, points: np.ndarray) -> np.ndarray:
    """kappa of the residual Jacobian at the true solution of each point (inf where singular)."""
    mech, cfg = problem_mechanism(problem, folder)
    prob = make_problem(cfg, mech, targets_of(mech, points))
    x = points[:, None, :]
    if prob.has_jacobian:
        jac = prob.jacobian(x)[:, 0]
    else:      # central differences (a plug-in mechanism without an analytic Jacobian)
        h = 1e-6 * np.maximum(1.0, np.abs(points))
        cols = []
        for j in range(points.shape[1]):
            e = np.zeros_like(points)
            e[:, j] = h[:, j]
            cols.append((prob.residuals((points + e)[:, None]) - prob.residuals((points - e)[:, None]))[:, 0]
                        / (2 * h[:, j, None]))
        jac = np.stack(cols, axis=-1)
    s = np.linalg.svd(jac, compute_uv=False)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(s[:, -1] > 0, s[:, 0] / s[:, -1], np.inf)


def drawing_box(mech) -> tuple[np.ndarray, np.ndarray]:
    """The box the pose sets are drawn in: the mechanism's bounds, except that a URDF arm's
    (or MJCF arm's) bounds in degrees are rounded to the nearest 9th decimal, as fkopt read every limit
    when kinbench v2 and v3 were released. The arm's own bounds now never lie outside the
    file's limits in radians (:func:`fkopt.mechanisms.urdf._inward`, issue 41: rounding to the
    nearest moved them outward by up to 8.7e-12 rad), so :func:`generate` draws in this box --
    the released sets regenerate bit for bit -- and clips every point to the arm's bounds: a
    point in the sliver between the two (at most 5e-10 deg wide) moves onto the limit. No
    frozen set holds one (tests/test_newcomer.py checks every frozen joint against the limits)."""
    lo, hi = mech.bounds[:, 0].copy(), mech.bounds[:, 1].copy()
    if isinstance(mech, URDFArm):             # URDF and MJCF arms (MJCFArm reads its limits the same way)
        for i, unit in enumerate(mech.unknown_units):
            if unit == "deg":
                lo[i], hi[i] = round(float(lo[i]), 9), round(float(hi[i]), 9)
    return lo, hi


def generate(problem, seed: int, n: int = POSES, folder: Path | None = None,
             measure: str = "condition") -> tuple[dict, dict]:
    """Points of every set of ``problem`` and what the manifest records of their generation.
    ``measure`` picks the near-singular set: ``"condition"`` (v1, v2: kappa of the residual
    Jacobian above its 95th percentile) or ``"sigma"`` (v3: the unit-free smallest singular value
    of :func:`fkopt.kinbench.measures.unit_free_sigma_min` below its 5th percentile)."""
    mech, _ = problem_mechanism(problem, folder)
    lo, hi = drawing_box(mech)
    inside = lambda pts: np.clip(pts, mech.bounds[:, 0], mech.bounds[:, 1])   # noqa: E731 (bit-identical inside)
    dim = len(lo)
    out, info = {}, {}
    rng = set_rng(seed, problem.name, "uniform")
    out["uniform"] = inside(lo + rng.random((n, dim)) * (hi - lo))
    rng = set_rng(seed, problem.name, "near-singular")
    cand = inside(lo + rng.random((CANDIDATES, dim)) * (hi - lo))
    if measure == "condition":
        kappa = condition_numbers(problem, folder, cand)
        bound = float(np.quantile(kappa[np.isfinite(kappa)], SINGULAR_QUANTILE))
        picked = np.flatnonzero(kappa > bound)[:n]
        info["near-singular"] = {"measure": "condition number of the residual Jacobian at the solution",
                                 "bound": float(f"{bound:.6g}"), "quantile": SINGULAR_QUANTILE,
                                 "candidates": CANDIDATES}
    elif measure == "sigma":
        length = characteristic_length(mech, cand)
        sigma = unit_free_sigma_min(mech, cand, length)
        bound = float(np.quantile(sigma[np.isfinite(sigma)], 1.0 - SINGULAR_QUANTILE))
        picked = np.flatnonzero(sigma < bound)[:n]
        info["near-singular"] = {"measure": "unit-free smallest singular value of the Jacobian (lengths / L)",
                                 "bound": float(f"{bound:.6g}"), "quantile": float(f"{1.0 - SINGULAR_QUANTILE:.6g}"),
                                 "candidates": CANDIDATES, "characteristic_length": float(f"{length:.6g}")}
    else:
        raise FkoptError(f"pose sets: measure '{measure}' unknown; allowed: condition, sigma")
    out["near-singular"] = cand[picked]
    rng = set_rng(seed, problem.name, "boundary")
    u = rng.random((n, dim + 3))
    pts = lo + u[:, :dim] * (hi - lo)
    coord = np.floor(u[:, dim] * dim).astype(int)
    upper = u[:, dim + 1] < 0.5
    depth = u[:, dim + 2] * BOUNDARY_SHARE * (hi - lo)[coord]
    rows = np.arange(n)
    pts[rows, coord] = np.where(upper, hi[coord] - depth, lo[coord] + depth)
    out["boundary"] = inside(pts)
    info["boundary"] = {"share_of_range": BOUNDARY_SHARE}
    printed = PRINTED.get(problem.name, [])
    out["printed"] = (np.array([mech.vector(p, mech.unknown_names, f"printed pose of {problem.name}")
                                for p in printed]) if printed else np.empty((0, dim)))
    return out, info


def csv_bytes(names: tuple[str, ...], points: np.ndarray) -> bytes:
    buf = io.StringIO()
    buf.write(",".join(names) + "\n")
    for row in points:
        buf.write(",".join(f"{v:.17g}" for v in row) + "\n")
    return buf.getvalue().encode("ascii")


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def write_pose_sets(config, folder: Path, poses: int = POSES, measure: str = "condition") -> Path:
    """Generate and write every set of every problem of ``config`` into ``folder`` (frozen data:
    run once per version, then commit the folder). v1 and v2: 20 poses, ``condition``; v3: 100
    poses, ``sigma`` (recorded in the manifest, only when not v1's/v2's defaults)."""
    folder = Path(folder)
    manifest = {"version": folder.name, "seed": config.seed, "poses_per_set": poses,
                "generator": "fkopt.kinbench.posesets.generate", "problems": {}}
    if measure != "condition":
        manifest["near_singular_measure"] = measure
    for problem in config.problems:
        sets, info = generate(problem, config.seed, poses, files_folder(config), measure)
        mech, _ = problem_mechanism(problem, files_folder(config))
        entry = {"mechanism": problem.mechanism.model_dump(mode="json"), "unknowns": list(mech.unknown_names),
                 "sets": {}}
        (folder / problem.name).mkdir(parents=True, exist_ok=True)
        for name, pts in sets.items():
            data = csv_bytes(mech.unknown_names, pts)
            (folder / problem.name / f"{name}.csv").write_bytes(data)
            entry["sets"][name] = {"file": f"{problem.name}/{name}.csv", "sha256": sha256_bytes(data),
                                   "poses": len(pts), **info.get(name, {})}
        manifest["problems"][problem.name] = entry
    (folder / MANIFEST).write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    return folder


def pose_set_folder(config, files: Path | None = None) -> Path:
    """The suite's pose-set folder, in ``files`` (default: the suite file's folder,
    :func:`fkopt.kinds.experiment.config.files_folder`)."""
    base = files if files is not None else files_folder(config)
    return Path(base if base is not None else ".") / config.pose_sets


#: Largest manifest and pose-set CSV read (bytes); fkopt's own are kilobytes.
MAX_MANIFEST_BYTES = 1 << 20
MAX_SET_BYTES = 16 << 20


def _manifest_problem(manifest, mpath: Path, problem) -> dict:
    """The manifest's entry of ``problem``, its shape checked (one line naming the field)."""
    problems = manifest.get("problems") if isinstance(manifest, dict) else None
    if not isinstance(problems, dict):
        raise FkoptError(f"{mpath}: field 'problems' must be a mapping of problem name to its sets")
    entry = problems.get(problem.name)
    if entry is None:
        raise FkoptError(f"{mpath}: no pose sets for problem '{problem.name}' "
                         f"(has: {', '.join(map(str, problems))[:200]})")
    where = f"{mpath}: problems.{problem.name}"
    if not isinstance(entry, dict):
        raise FkoptError(f"{where}: must be a mapping with mechanism, unknowns and sets")
    for key, kind, what in (("mechanism", dict, "a mapping (the mechanism spec)"),
                            ("unknowns", list, "a list of the unknowns' names"),
                            ("sets", dict, "a mapping of set name to its file, sha256 and poses")):
        if not isinstance(entry.get(key), kind):
            raise FkoptError(f"{where}.{key}: {'missing' if key not in entry else 'wrong type'}; must be {what}")
    if not entry["unknowns"] or not all(isinstance(u, str) for u in entry["unknowns"]):
        raise FkoptError(f"{where}.unknowns: must be a non-empty list of names")
    return entry


def _set_meta(entry: dict, where: str, name: str) -> dict:
    meta = entry["sets"].get(name)
    if meta is None:
        raise FkoptError(f"{where}: has no set '{name}' (has: {', '.join(map(str, entry['sets']))[:200]})")
    if not isinstance(meta, dict):
        raise FkoptError(f"{where}.sets.{name}: must be a mapping with file, sha256 and poses")
    if not isinstance(meta.get("file"), str) or not meta["file"]:
        raise FkoptError(f"{where}.sets.{name}.file: must be the set's path inside the pose-set folder")
    sha = meta.get("sha256")
    if not isinstance(sha, str) or len(sha) != 64 or any(c not in "0123456789abcdef" for c in sha):
        raise FkoptError(f"{where}.sets.{name}.sha256: must be 64 lowercase hex digits (the file's SHA-256)")
    poses = meta.get("poses")
    if poses is not None and (not isinstance(poses, int) or isinstance(poses, bool) or poses < 0):
        raise FkoptError(f"{where}.sets.{name}.poses: must be a non-negative integer")
    return meta


def parse_set_csv(data: bytes, path: Path, unknowns: list[str]) -> np.ndarray:
    """The points of a pose-set CSV: ASCII, a header of exactly ``unknowns``, every row that
    many finite numbers; anything else one line naming the file, the line and what is allowed
    (no cell of the file is quoted beyond a short sanitised token)."""
    check_csv_shape(data, str(path))        # line length and fields bounded before any split
    try:
        text = data.decode("ascii")
    except UnicodeDecodeError as err:
        raise FkoptError(f"{path}: not ASCII text (byte 0x{data[err.start]:02x} at offset {err.start}); a pose set "
                         "is a CSV of numbers") from None
    lines = text.splitlines()
    if not lines:
        raise FkoptError(f"{path}: empty; needs the header {','.join(unknowns)} and one row per pose")
    if lines[0].split(",") != unknowns:
        raise FkoptError(f"{path}: header '{short_token(lines[0])}' differs from the unknowns "
                         f"{','.join(unknowns)}")
    pts = np.empty((len(lines) - 1, len(unknowns)))
    for i, line in enumerate(lines[1:]):
        cells = line.split(",")
        if len(cells) != len(unknowns):
            raise FkoptError(f"{path}: line {i + 2} has {len(cells)} cells, needs {len(unknowns)} "
                             f"({','.join(unknowns)})")
        try:
            pts[i] = [float(c) for c in cells]
        except ValueError:
            raise FkoptError(f"{path}: line {i + 2}: not a number (needs {len(unknowns)} finite numbers)") from None
        if not np.all(np.isfinite(pts[i])):
            raise FkoptError(f"{path}: line {i + 2}: not a finite number (NaN and inf are not poses)")
    return pts


def load_pose_sets(config, files: Path | None = None) -> tuple[dict[tuple[str, str], np.ndarray], dict]:
    """{(problem, set): points} of ``config`` (the first ``config.poses`` of each set), checked
    against the manifest's SHA-256 and mechanism specs; and the manifest. Every file is read
    with :func:`fkopt.files.read_input`'s bounds (a set's file must lie inside the set folder);
    the manifest's shape and every set file's contents are checked (a digest proves a file is
    the one the manifest names, not that either is well-formed): one line naming the file.
    ``files``: where the suite's relative files are (:func:`pose_set_folder`)."""
    folder = pose_set_folder(config, files)
    mpath = folder / MANIFEST
    if not mpath.exists() and not mpath.is_symlink():
        raise FkoptError(f"{mpath}: pose-set manifest not found (pose_sets: '{config.pose_sets}' names a "
                         "folder beside the suite file)")
    raw = read_input(mpath, MAX_MANIFEST_BYTES, within=folder)
    manifest = parse_json(raw, str(mpath))
    if not isinstance(manifest, dict):
        raise FkoptError(f"{mpath}: must be a JSON mapping (version, seed, problems)")
    out = {}
    for problem in config.problems:
        entry = _manifest_problem(manifest, mpath, problem)
        where = f"{mpath}: problems.{problem.name}"
        if entry["mechanism"] != problem.mechanism.model_dump(mode="json"):
            raise FkoptError(f"problems[{problem.name}].mechanism: differs from the mechanism its pose sets "
                             f"in {folder} were generated for; a new mechanism needs new pose sets (a new version)")
        for name in config.sets:
            meta = _set_meta(entry, where, name)
            path = folder / meta["file"]
            data = read_input(path, MAX_SET_BYTES, field=f"{where}.sets.{name}.file", within=folder)
            if sha256_bytes(data) != meta["sha256"]:
                raise FkoptError(f"{path}: SHA-256 {sha256_bytes(data)[:16]}... differs from the manifest's "
                                 f"{meta['sha256'][:16]}...; the frozen pose set was changed")
            pts = parse_set_csv(data, path, entry["unknowns"])
            if meta.get("poses") is not None and meta["poses"] != len(pts):
                raise FkoptError(f"{where}.sets.{name}.poses: {meta['poses']}, but {path} has {len(pts)} poses")
            out[(problem.name, name)] = pts[: config.poses] if config.poses else pts
    check_release(config, manifest, files)      # a released version: every file as released, not only as its manifest says
    return out, manifest
