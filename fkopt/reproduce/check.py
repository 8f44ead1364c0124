"""Regression check: rerun stored results from their recorded config and compare (``fkopt check``).

One checker for every kind of config (experiments, studies, assembly searches). For each
results folder ``<paper>/<name>/``:

1. ``meta.json`` must exist and be readable, with the config; a missing or unreadable
   ``meta.json`` is a failure (never skipped);
2. every deterministic file must still have the SHA-256 recorded in ``meta.json`` when it was
   written (``files``), and no recorded file may be missing -- any edit of any stored table is
   caught, on any platform;
3. on every platform: ``summary.csv`` must hold the statistics of the stored ``runs.csv``
   (:func:`fkopt.run.compare.summary_consistency`), and the fitness of every stored run, recomputed
   from its stored ``x`` (:func:`recomputed_fitness`), must equal the stored fitness within what
   the CSV's 10 significant digits of ``x`` allow;
4. the config is validated and rerun in this process into a scratch folder; the deterministic
   files (all CSVs but the timing files, and ``meta.json``) are compared by the rules of the
   platform tier (:func:`fkopt.run.provenance.platform_tier`, :mod:`fkopt.run.compare`): byte for byte
   where the stored fingerprint equals this machine's, BLAS-free rows exactly and the rest by the
   cross-platform rules where only the BLAS part differs, the cross-platform rules elsewhere
   (``tier=`` forces one: ``fkopt check --tolerant`` is the "blas" tier); the rerun takes the
   numerics mode recorded in ``env.json`` (``FKOPT_NUMERICS`` set from it: :func:`stored_numerics`);
5. the paper's claims recomputed with the rerun in place must keep the verdicts stored in
   ``<paper>/claims.csv`` (:func:`fkopt.reproduce.drift.rerun_verdict_drift`), and the stored
   verdict files must be what the current engine writes from the stored results, columns and
   rows (:func:`verdict_files`): a file an older engine wrote fails.

A mismatch names the experiment, the file, the row, the column and both values. Figures are
not compared (they depend on the plotting library's version).
"""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.run.compare import Mismatch, Rules, compare_folders, deterministic_files, sha256, summary_consistency
from fkopt.errors import FkoptError
from fkopt.files import odd_entries, parse_json, read_stored, read_stored_csv
import fkopt.kinbench  # noqa: F401 (registers every built-in kind of config)
from fkopt.registry import algorithm_class, mechanism_class, registered_only
from fkopt.run.pipeline import config_kind, from_dict, rerun_files
from fkopt.run.tasks import task_file_problems
from fkopt.numerics import path as numerics_path
from fkopt.run.provenance import ANY, BLAS, ENV_FILE, EXACT, platform_tier
from fkopt.reproduce.claims import CLAIMS_FILE, COLUMNS, TIMING_CLAIMS_FILE, claims_frame
from fkopt.reproduce.drift import rerun_verdict_drift
from fkopt.reproduce.engine import judge_paper
from fkopt.reproduce.store import Experiment, Store

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


def stored_tier(exp: Experiment) -> str:
    """The platform tier of a stored result on this machine (from its env.json's fingerprint)."""
    try:
        stored = parse_json(read_stored(exp.folder, ENV_FILE), ENV_FILE).get("fingerprint")
    except (OSError, ValueError, AttributeError, FkoptError):
        return ANY
    return platform_tier(stored)


def stored_numerics(exp: Experiment) -> str:
    """The ``FKOPT_NUMERICS`` mode a stored result ran under (its env.json's ``numerics.mode``;
    'auto' for results stored before the record existed: :func:`fkopt.numerics.path.recorded`)."""
    try:
        env = parse_json(read_stored(exp.folder, ENV_FILE), ENV_FILE)
    except (OSError, ValueError, FkoptError):
        env = None
    return numerics_path.recorded(env)


def rules_for(exp: Experiment, tier: str) -> Rules:
    """The comparison rules of ``exp``: which algorithm labels are path-dependent (a BLAS call may
    lie on their path: see ``Algorithm.blas_free`` and ``Mechanism.blas_free_fitness``), and the
    fitness at which a run counts as reached (the config's threshold)."""
    cfg = exp.config if isinstance(exp.config, dict) else {}
    mechs = [p.get("mechanism") or {} for p in cfg.get("problems") or []] or [cfg.get("mechanism") or {}]
    try:                # a suite has several problems: its rows are BLAS-free only if every fitness is
        classes = [mechanism_class(m.get("name")) for m in mechs]
        mech_ok = all(getattr(c, "blas_free_fitness", False) for c in classes)
        isolated = all(c.kind == "parallel" for c in classes)
    except Exception:   # an unknown or unloadable mechanism: assume BLAS on its path
        mech_ok, isolated = False, False
    free = set()
    for a in (cfg.get("algorithms") or []) + (cfg.get("solvers") or []):
        try:
            if mech_ok and getattr(algorithm_class(a.get("name")), "blas_free", False):
                free.add(str(a.get("label") or a.get("name")))
        except Exception:
            pass
    threshold = cfg.get("threshold")
    reach = float(threshold) if isinstance(threshold, (int, float)) and threshold > 0 else Rules.reach
    return Rules(tier, lambda label: label not in free, reach, isolated)


def recomputed_fitness(exp: Experiment, config) -> list[Mismatch]:
    """The fitness of every stored run of an experiment or study recomputed from its stored ``x``, against
    the stored ``final_fitness`` (on every platform).

    ``runs.csv`` keeps 10 significant digits, so x is known to within d_i = 5e-10 |x_i|. The
    bound on |f(x_true) - f(x_stored)| is taken from f itself: 4 x sum_i max(|f(x + d_i e_i) -
    f(x)|, |f(x - d_i e_i) - f(x)|) (first order, with a factor 2 for the curvature of a squared
    residual and 2 for safety), plus the stored fitness' own rounding (5e-10 relative).
    """
    stored_problems = config_kind(config).stored_problems
    if stored_problems is None or not (exp.folder / "runs.csv").is_file():
        return []
    label = _label(exp)
    try:
        runs = read_stored_csv(exp.folder, "runs.csv")
    except (OSError, ValueError, pd.errors.ParserError, UnicodeDecodeError, FkoptError) as err:
        return [Mismatch(label, "runs.csv", "-", "file", f"unreadable ({err})", "readable", "readable CSV")]
    groups = stored_problems(config, runs)
    out = []
    for where, sel, make in groups:
        rows = runs[sel]
        if rows.empty:
            continue
        problem = make()
        xs = [c for c in runs.columns if c.startswith("x_")]
        if len(xs) != problem.dim:
            return [Mismatch(label, "runs.csv", where, "x", f"{len(xs)} x columns", f"{problem.dim} variables",
                             "one x column per variable")]
        x = rows[xs].to_numpy(float)
        stored = rows["final_fitness"].to_numpy(float)
        d = 5e-10 * np.abs(x)
        eye = np.eye(problem.dim)[None] * d[:, None, :]                 # row k: d_k e_k
        pts = np.concatenate([x[:, None, :], x[:, None, :] + eye, x[:, None, :] - eye], axis=1)
        with np.errstate(all="ignore"):
            f = np.asarray(problem.fitness(pts), dtype=float)           # (runs, 1 + 2 dim)
        f0 = f[:, 0]
        change = np.abs(f[:, 1:] - f0[:, None]).reshape(len(x), 2, problem.dim).max(axis=1).sum(axis=1)
        tol = 4.0 * change + 5e-10 * np.abs(stored) + 1e-300
        bad = ~(np.abs(f0 - stored) <= tol)
        for i in np.flatnonzero(bad)[:3]:
            row = rows.iloc[i]
            out.append(Mismatch(label, "runs.csv", f"{where} / {row['algorithm']} / {row['run']}",
                                "final_fitness", float(stored[i]), float(f0[i]),
                                f"fitness(x) of the stored x, within {tol[i]:.2g} (10 digits of x; every platform)"))
    return out


def check_experiment(exp: Experiment, config=None, exact: bool | None = None, tier: str | None = None,
                     allow_plugins: bool = False) -> list[Mismatch]:
    """Mismatches of one stored result (any kind) against a rerun; ``[]`` when it matches.

    ``tier`` forces the comparison rules (``"exact"``, ``"blas"``, ``"any"``; see
    :func:`fkopt.run.provenance.platform_tier`); ``exact=True``/``False`` is ``"exact"``/``"any"``. By
    default the tier follows the stored platform fingerprint.

    The stored config names its mechanism and algorithms: only built-in names, adapters and
    registered entry points are resolved -- a direct reference ``package.module:Class`` in
    someone else's meta.json is refused, not imported -- unless ``allow_plugins``
    (:func:`fkopt.registry.registered_only`).
    """
    with registered_only(not allow_plugins):
        return _check_experiment(exp, config, exact, tier)


def _check_experiment(exp: Experiment, config, exact: bool | None, tier: str | None) -> list[Mismatch]:
    label = _label(exp)
    problem = exp.meta_error()
    if problem:
        return [Mismatch(label, "meta.json", "-", "file", problem, "a readable meta.json with the config",
                         "present and readable")]
    odd = odd_entries(exp.folder)
    if odd:       # nothing of the folder is read through a link or from a FIFO or device
        return [Mismatch(label, name, "-", "file", what, "a regular file of the folder", "regular files only")
                for name, what in odd]
    out = integrity(exp)
    # kept task files: digests of tasks/manifest.json
    out += [Mismatch(label, name, "-", "sha256", why, "recorded in tasks/manifest.json", "unchanged since written")
            for name, why in task_file_problems(exp.folder)]
    if config is None:
        try:
            config = from_dict(dict(exp.config), f"{label}/meta.json config")
        except FkoptError as err:
            return out + [Mismatch(label, "meta.json", "-", "config", str(err), "a valid config", "valid")]
    if tier is None:
        tier = stored_tier(exp) if exact is None else (EXACT if exact else ANY)
    if tier not in (EXACT, BLAS, ANY):
        raise FkoptError(f"tier: '{tier}' unknown; allowed: {EXACT}, {BLAS}, {ANY}")
    out += summary_consistency(label, exp.folder)
    out += recomputed_fitness(exp, config)
    out += verdict_files(exp)
    out += board_from_answers(label, exp, config)
    tmp = Path(tempfile.mkdtemp(prefix="fkopt-check-"))
    try:
        with numerics_path.forced(stored_numerics(exp)):          # the path that made it
            rerun_files(config, tmp, exp.meta.get("config_file"))
        names = sorted(set(deterministic_files(exp.folder)) | set(deterministic_files(tmp)))
        order = [n for n in FIRST if n in names] + [n for n in names if n not in FIRST and n != "meta.json"]
        order += ["meta.json"]
        out += compare_folders(label, exp.folder, tmp, rules_for(exp, tier), files=order)
        out += rerun_verdict_drift(exp, tmp)          # a claim's verdict must not change either
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return out


def board_from_answers(label: str, exp: Experiment, config) -> list[Mismatch]:
    """What the kind judges again in a stored folder besides the rerun (:attr:`fkopt.run.tasks.Kind.recheck`:
    a kinbench v3 suite's stored answers judged again with fkopt's FK and its per-robot board
    recomputed from them, :func:`fkopt.kinbench.verify.reverify`); timing files themselves are
    never compared with a rerun's."""
    recheck = config_kind(config).recheck
    return [] if recheck is None else [Mismatch(label, *row) for row in recheck(exp.folder, config, exp.meta)]


#: The engine's verdict files of a paper folder, judged once per check however many of its experiments
#: are checked: (paper folder, the stat of its verdict files and meta.json files) -> {file: frame}.
_JUDGED: dict = {}


def engine_verdict_files(root: Path, paper: str) -> dict[str, pd.DataFrame]:
    """{file name: rows} of the verdict files the current engine writes for ``paper`` from the results
    stored under ``root`` (:func:`fkopt.reproduce.report.claims_files`'s rule: claims.csv where the
    paper's claims are judged here, timing_claims.csv when it has timing claims)."""
    folder = root / paper
    stats = tuple(sorted((str(f), f.stat().st_mtime_ns, f.stat().st_size)
                         for f in [*folder.glob("*.csv"), *folder.glob("*/meta.json")] if f.is_file()))
    key = (str(folder.resolve()), stats)
    if key not in _JUDGED:
        judged = judge_paper(paper, Store(root))
        files = {}
        if judged is not None:
            files[CLAIMS_FILE] = claims_frame(judged[0])
            if judged[1]:
                files[TIMING_CLAIMS_FILE] = claims_frame(judged[1])
        _JUDGED.clear()
        _JUDGED[key] = files
    return _JUDGED[key]


def verdict_files(exp: Experiment) -> list[Mismatch]:
    """The stored verdict files of ``exp``'s paper (``claims.csv``, ``timing_claims.csv``) must be, with
    their columns and row for row (id, claim, verdict, condition), what the current engine writes from
    the stored results. A file an older engine wrote fails: other columns (the stale results/peers
    files had only claim, verdict), a claim added, renamed or dropped, a changed verdict or condition, a
    file the engine writes none of in this tree (a paper's claims are judged only where one of their
    experiments is stored: :func:`fkopt.reproduce.engine.judged_here`), or a missing one in a tree
    written by ``fkopt reproduce`` (REPORT.md at its root). Judged from the stored runs, so on every
    platform (timing verdicts from the stored timed runs: check measures no time); a rerun's verdicts
    are :func:`fkopt.reproduce.drift.rerun_verdict_drift`'s. The fix is ``fkopt report RESULTS``."""
    root = exp.folder.parents[1]
    folder = exp.folder.parent
    names = ("claims.csv", TIMING_CLAIMS_FILE)
    stored_any = any((folder / n).is_file() for n in names)
    if not stored_any and not (root / "REPORT.md").is_file():
        return []          # one experiment folder copied elsewhere: no verdict files expected
    paper = exp.paper
    try:
        expected = engine_verdict_files(root, paper)
    except (OSError, ValueError, pd.errors.ParserError, UnicodeDecodeError, FkoptError) as err:
        return [Mismatch(paper, "claims.csv", "-", "file", f"unjudgeable ({err})", "judged", "readable results")]
    fix = "what this engine writes from the stored results (every platform; fkopt report RESULTS rewrites it)"
    out = []
    for name in names:
        file = folder / name
        want = expected.get(name)
        if not file.is_file():
            if want is not None:
                out.append(Mismatch(paper, name, "-", "file", "missing", "present",
                                    f"{paper} has claims: its {name} is part of the stored result"))
            continue
        if want is None:
            out.append(Mismatch(paper, name, "-", "file", "present", "absent",
                                f"written by an older engine: this engine writes no {name} for {paper} in this tree "
                                "(its claims are judged where their experiments are stored)"))
            continue
        try:
            stored = read_stored_csv(folder, name, dtype=str, keep_default_na=False)
        except (OSError, ValueError, pd.errors.ParserError, UnicodeDecodeError, FkoptError) as err:
            out.append(Mismatch(paper, name, "-", "file", f"unreadable ({err})", "readable", "readable CSV"))
            continue
        if list(stored.columns) != COLUMNS:
            out.append(Mismatch(paper, name, "-", "columns", ", ".join(map(str, stored.columns)), ", ".join(COLUMNS),
                                "written by an older engine: " + fix))
            continue
        a = {r["id"]: r for r in stored.to_dict("records")}
        b = {r["id"]: r for r in want.astype(str).to_dict("records")}
        for key in sorted(set(a) | set(b)):
            for col in ("verdict", "condition", "claim"):
                old, new = a.get(key, {}).get(col, "(absent)"), b.get(key, {}).get(col, "(absent)")
                if old != new:
                    out.append(Mismatch(paper, name, key[:90], col, old[:120], new[:120], fix))
                    break
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
