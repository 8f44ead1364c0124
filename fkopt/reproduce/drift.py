"""Verdicts that a rerun changed (``fkopt check``): the stored ``<paper>/claims.csv`` (and
``timing_claims.csv``) against the verdicts the one engine (:mod:`.engine`) computes now.

Kept apart from :mod:`.claims` (the vocabulary the engine uses) so the two never import each other.
"""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from fkopt.errors import FkoptError
from fkopt.run.compare import Mismatch, timing_files
from fkopt.reproduce.claims import CLAIMS_FILE, TIMING_CLAIMS_FILE, _key, claims_frame, read_claims
from fkopt.reproduce.engine import judge_paper, load
from fkopt.reproduce.store import Store


def verdict_changes(root: str | Path, timing: bool = False) -> list[tuple[str, str, str, str]]:
    """(paper, claim, stored verdict, recomputed verdict) for every non-timing claim whose verdict
    computed from the results under ``root`` differs from the stored ``<paper>/claims.csv``
    (``(absent)`` when a claim appeared or disappeared). ``timing=True``: the timing claims against
    ``<paper>/timing_claims.csv`` instead (meaningful only on the platform that measured them)."""
    root = Path(root)
    store = Store(root)
    out = []
    for paper in store.papers():
        file = root / paper / (TIMING_CLAIMS_FILE if timing else CLAIMS_FILE)
        judged = judge_paper(paper, store)
        if judged is None or not file.exists():
            continue
        stored = read_claims(file)
        now = claims_frame(judged[1] if timing else judged[0])
        by_id = "id" in stored and (stored["id"] != "").all()
        s = dict(zip(_key(stored), zip(stored.claim, stored.verdict)))
        n = dict(zip(now["id"] if by_id else now["claim"], zip(now.claim, now.verdict)))
        for key in sorted(set(s) | set(n)):
            a, b = s.get(key, (None, "(absent)")), n.get(key, (None, "(absent)"))
            if a[1] != b[1]:
                out.append((paper, f"{key}: {a[0] or b[0]}" if by_id else key, a[1], b[1]))
    return out


def rerun_verdict_drift(exp, rerun_folder: str | Path) -> list:
    """Verdicts of ``exp``'s paper recomputed with the rerun of ``exp`` in place of the stored folder,
    against the stored ``claims.csv`` (``fkopt check``): one :class:`~.check.Mismatch` per change."""
    if not (exp.folder.parent / CLAIMS_FILE).exists():
        return []
    try:
        read_claims(exp.folder.parent / CLAIMS_FILE)
    except FkoptError as err:
        return [Mismatch(f"{exp.paper}/{exp.name}", CLAIMS_FILE, "-", "file", str(err),
                         "a UTF-8 CSV with claim, verdict", "readable")]
    tmp = Path(tempfile.mkdtemp(prefix="fkopt-claims-"))
    try:
        shutil.copytree(exp.folder.parent, tmp / exp.paper)
        shutil.rmtree(tmp / exp.paper / exp.name)
        shutil.copytree(rerun_folder, tmp / exp.paper / exp.name)
        for other in _other_papers_experiments(exp.paper):   # a claim judged on another paper's runs
            if (exp.folder.parents[1] / other).is_dir() and not (tmp / other).exists():
                shutil.copytree(exp.folder.parents[1] / other, tmp / other)   # without that paper's claims.csv
        # check's rerun measures no time: the stored timings stand in,
        for name in timing_files():            # so judging the paper (timing claims included) can read them
            if (exp.folder / name).is_file() and not (tmp / exp.paper / exp.name / name).exists():
                shutil.copy2(exp.folder / name, tmp / exp.paper / exp.name / name)
        changes = verdict_changes(tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return [Mismatch(f"{exp.paper}/{exp.name}", CLAIMS_FILE, text[:90], "verdict", a, b, "same verdict")
            for _, text, a, b in changes]


def _other_papers_experiments(paper: str) -> list[str]:
    """``other_paper/name`` of every experiment of another paper that ``paper``'s claims are judged on."""
    specs = (load(paper) or {}).get("claims") or []
    return sorted({str(c["experiment"]) for c in specs if "/" in str(c.get("experiment", ""))})
