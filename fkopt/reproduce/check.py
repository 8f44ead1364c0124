"""Regression check: rerun stored results from their recorded config and compare (``fkopt check``).

One checker for every kind of config (experiments, studies, assembly searches). For each
results folder ``<paper>/<name>/``:

1. ``meta.json`` must exist and be readable, with the config; a missing or unreadable
   ``meta.json`` is a failure (never skipped);
2. every deterministic file must still have the SHA-256 recorded in ``meta.json`` when it was
   written (``files``), and no recorded file may be missing -- any edit of any stored table is
   caught, on any platform;
3. the config is validated and rerun in this process into a scratch folder; the deterministic
   files (all CSVs but the timing files, and ``meta.json``) are compared **byte for byte** when
   the platform fingerprint stored in ``env.json`` equals this machine's, and by the documented
   distribution-level tolerances of :mod:`fkopt.compare` otherwise.
4. the paper's claims recomputed with the rerun in place must keep the verdicts stored in
   ``<paper>/claims.csv`` (:func:`fkopt.reproduce.claims.rerun_verdict_drift`).

A mismatch names the experiment, the file, the row, the column and both values. Figures are
not compared (they depend on the plotting library's version).
"""
from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path

from ..compare import (FITNESS_FLOOR, LOG10_TOL, RATE_TOL, COUNT_RTOL, EXACT_RTOL, Mismatch,  # noqa: F401
                       compare_folders, compare_tables, deterministic_files, sha256)
from ..errors import FkoptError
from ..experiment.kinds import from_dict, rerun_files
from ..provenance import ENV_FILE, fingerprint
from .store import Experiment, Store

#: Compared first (so the first mismatch is the most telling), then the rest, meta.json last.
FIRST = ("summary.csv", "values.csv", "inputs.csv")


def _label(exp: Experiment) -> str:
    return f"{exp.paper}/{exp.name}"


def integrity(exp: Experiment) -> list[Mismatch]:
    """Stored files against the digests recorded in meta.json."""
    label = _label(exp)
    recorded = exp.meta.get("files")
    if not isinstance(recorded, dict):
        return [Mismatch(label, "meta.json", "-", "files", "no file digests", "digests",
                         "meta.json records the SHA-256 of every table (regenerate the result)")]
    out = []
    for name in sorted(set(recorded) | set(n for n in deterministic_files(exp.folder) if n != "meta.json")):
        path = exp.folder / name
        if name not in recorded:
            out.append(Mismatch(label, name, "-", "file", "present", "not recorded in meta.json", "recorded"))
        elif not path.is_file():
            out.append(Mismatch(label, name, "-", "file", "missing", "recorded in meta.json", "present"))
        else:
            digest = sha256(path)
            if digest != recorded[name]:
                out.append(Mismatch(label, name, "-", "sha256", digest[:16], str(recorded[name])[:16],
                                    "unchanged since written (SHA-256 in meta.json)"))
    return out


def same_platform(exp: Experiment) -> bool:
    """Does the fingerprint in the stored env.json equal this machine's?"""
    try:
        stored = json.loads((exp.folder / ENV_FILE).read_text(encoding="utf-8")).get("fingerprint")
    except (OSError, ValueError, AttributeError):
        return False
    return stored == fingerprint()


def check_experiment(exp: Experiment, config=None, exact: bool | None = None,
                     allow_plugins: bool = False) -> list[Mismatch]:
    """Mismatches of one stored result (any kind) against a rerun; ``[]`` when it matches.

    ``exact`` forces the byte-for-byte (True) or the tolerant (False) comparison; by default it
    is chosen by the platform fingerprint. The stored config names its mechanism and algorithms:
    only built-in names and registered entry points are resolved (a direct reference
    ``package.module:Class`` in someone else's meta.json is refused, not imported) unless
    ``allow_plugins`` (:func:`fkopt.registry.registered_only`).
    """
    from ..registry import registered_only
    with registered_only(not allow_plugins):
        return _check_experiment(exp, config, exact)


def _check_experiment(exp: Experiment, config, exact: bool | None) -> list[Mismatch]:
    label = _label(exp)
    problem = exp.meta_error()
    if problem:
        return [Mismatch(label, "meta.json", "-", "file", problem, "a readable meta.json with the config",
                         "present and readable")]
    out = integrity(exp)
    if config is None:
        try:
            config = from_dict(dict(exp.config), f"{label}/meta.json config")
        except FkoptError as err:
            return out + [Mismatch(label, "meta.json", "-", "config", str(err), "a valid config", "valid")]
    exact = same_platform(exp) if exact is None else exact
    tmp = Path(tempfile.mkdtemp(prefix="fkopt-check-"))
    try:
        rerun_files(config, tmp, exp.meta.get("config_file"))
        names = sorted(set(deterministic_files(exp.folder)) | set(deterministic_files(tmp)))
        order = [n for n in FIRST if n in names] + [n for n in names if n not in FIRST and n != "meta.json"]
        order += ["meta.json"]
        out += compare_folders(label, exp.folder, tmp, exact, files=order)
        from .claims import rerun_verdict_drift   # a claim's verdict must not change either
        out += rerun_verdict_drift(exp, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return out


def select(store: Store, subset: str = "all", paper: str | None = None, name: str | None = None) -> list[Experiment]:
    """Results folders to check: ``all``, or ``ci`` (those whose config has ``check: ci``, the
    default). Folders without a readable meta.json are always selected (and fail)."""
    exps = store.folders(paper)
    if name is not None:
        exps = [e for e in exps if e.name == name]
    if subset == "ci":
        exps = [e for e in exps if e.meta_error() or e.config.get("check", "ci") == "ci"]
    return exps
