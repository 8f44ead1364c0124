"""What moved when ``fkopt reproduce`` regenerated a results tree: ``CHANGES.md`` at its root.

:func:`snapshot` reads the tree before the rerun (each result's deterministic files, its
``summary.csv``, each paper's ``claims.csv``); :func:`describe` compares it with the tree after
and says, per result, which files changed, which summary rows moved (the column, old -> new)
and which verdicts changed. The report (:mod:`.report`) includes it, so REPORT.md says what the
last regeneration moved, and nobody writes that list by hand.
"""
from __future__ import annotations

import json
import shutil
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from fkopt.errors import FkoptError
from fkopt.files import parse_csv, read_stored, read_text, write_file_atomically
from fkopt.run.compare import ANY, compare_folders
from fkopt.run.writers import deterministic_files, sha256
from fkopt.reproduce.check import rules_for
from fkopt.reproduce.claims import CLAIMS_FILE
from fkopt.reproduce.store import Store

CHANGES_FILE = "CHANGES.md"
#: Summary columns whose move is reported (the others follow from them or are settings).
WATCHED = ("mean_fitness", "median_fitness", "best_fitness", "success_rate", "mean_evaluations",
           "median_evaluations_to_threshold", "solutions_found")
MAX_ROWS = 12


@dataclass
class Snapshot:
    files: dict[str, dict[str, str]] = field(default_factory=dict)     # "paper/name" -> file -> sha256
    summaries: dict[str, str] = field(default_factory=dict)            # "paper/name" -> summary.csv text
    claims: dict[str, str] = field(default_factory=dict)               # paper -> claims.csv text
    #: a copy of every deterministic file (snapshot(keep=True)), to judge moved files afterwards
    copies: Path | None = None


def snapshot(root: str | Path, keep: Path | None = None, only: set[str] | None = None) -> Snapshot:
    """The state of a results tree (empty when there is none yet). With ``keep`` (an empty
    folder), its deterministic files are also copied there, for :func:`agreement`. ``only``:
    the results ("paper/name") to read, and their papers' claims (``fkopt reproduce`` into a
    folder of its own compares only what it reruns with the stored tree)."""
    root = Path(root)
    snap = Snapshot(copies=keep)
    if not root.is_dir():
        return snap
    store = Store(root)
    papers = None if only is None else {label.split("/")[0] for label in only}
    for exp in store.folders(None):
        label = f"{exp.paper}/{exp.name}"
        if only is not None and label not in only:
            continue
        names = deterministic_files(exp.folder)
        snap.files[label] = {f: sha256(exp.folder / f) for f in names if f != "meta.json"}
        if keep is not None:
            (keep / label).mkdir(parents=True, exist_ok=True)
            for f in names:
                shutil.copyfile(exp.folder / f, keep / label / f)
        if (exp.folder / "summary.csv").is_file():
            snap.summaries[label] = read_stored(exp.folder, "summary.csv").decode("utf-8", errors="replace")
    for paper in store.papers():
        if papers is not None and paper not in papers:
            continue
        file = root / paper / CLAIMS_FILE
        if file.is_file():
            snap.claims[paper] = read_stored(file.parent, file.name).decode("utf-8", errors="replace")
    return snap


def save_snapshot(snap: Snapshot, path: str | Path) -> None:
    """Keep a snapshot in a JSON file (``fkopt report --snapshot-to``), e.g. before ``make
    bench-suite`` reruns the suites, to say afterwards what they moved."""
    Path(path).write_text(json.dumps({"files": snap.files, "summaries": snap.summaries, "claims": snap.claims},
                                     sort_keys=True), encoding="utf-8")


def load_snapshot(path: str | Path) -> Snapshot:
    """A snapshot kept by :func:`save_snapshot`; one line naming the file when it is not one."""
    try:
        data = json.loads(read_text(path, 256 << 20))
        snap = Snapshot(dict(data["files"]), dict(data["summaries"]), dict(data["claims"]))
    except (ValueError, KeyError, TypeError):
        raise FkoptError(f"{path}: not a results snapshot (written by fkopt report --snapshot-to)") from None
    if not all(isinstance(v, dict) for v in snap.files.values()):
        raise FkoptError(f"{path}: not a results snapshot (written by fkopt report --snapshot-to)")
    return snap


def _table(text: str | None) -> pd.DataFrame | None:
    if not text:
        return None
    try:
        return parse_csv(text.encode("utf-8"), "stored table")
    except (FkoptError, ValueError, pd.errors.ParserError):
        return None


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def _summary_moves(before: str | None, after: str | None) -> list[str]:
    a, b = _table(before), _table(after)
    if a is None or b is None:
        return []
    keys = [k for k in ("case", "algorithm") if k in a.columns and k in b.columns]
    if not keys:
        return []
    merged = a.merge(b, on=keys, how="outer", suffixes=("_old", "_new"), indicator=True)
    lines = []
    for _, row in merged.iterrows():
        key = " / ".join(str(row[k]) for k in keys)
        if row["_merge"] != "both":
            lines.append(f"{key}: {'new row' if row['_merge'] == 'right_only' else 'row removed'}")
            continue
        moved = []
        for col in WATCHED:
            if f"{col}_old" not in row or f"{col}_new" not in row:
                continue
            old, new = row[f"{col}_old"], row[f"{col}_new"]
            if not (pd.isna(old) and pd.isna(new)) and old != new:
                moved.append(f"{col} {_fmt(old)} → {_fmt(new)}")
        if moved:
            lines.append(f"{key}: " + ", ".join(moved))
    return lines


def _claim_moves(before: str | None, after: str | None) -> list[str]:
    a, b = _table(before), _table(after)
    if a is None or b is None or "claim" not in a.columns or "claim" not in b.columns:
        return []
    by_id = all("id" in df.columns and df["id"].notna().all() and (df["id"].astype(str) != "").all() for df in (a, b))

    def keyed(df: pd.DataFrame) -> dict[str, str]:
        if by_id:   # the stable id (one per reading): a reworded claim or condition is no move
            return {str(i): str(v) for i, v in zip(df["id"], df["verdict"])}
        # older files without ids: one row per reading, the condition tells them apart
        # an all-empty condition column reads back as float NaN: blank it as text (fillna("") on float64 is
        # deprecated in pandas)
        cond = ([("" if pd.isna(c) else str(c)) for c in df["condition"]] if "condition" in df.columns
                else [""] * len(df))
        return {str(c) + (f" [under: {k}]" if k else ""): str(v)
                for c, k, v in zip(df["claim"], cond, df["verdict"])}
    old, new = keyed(a), keyed(b)
    texts = {**dict(zip(a["id"].astype(str), a["claim"])), **dict(zip(b["id"].astype(str), b["claim"]))} if by_id else {}
    out = []
    for key in sorted(set(old) | set(new)):
        if old.get(key) != new.get(key):
            label = f"{key} ({str(texts[key])[:80]})" if by_id else key[:110]
            out.append(f"{label}: {old.get(key, '(new claim)')} → {new.get(key, '(claim removed)')}")
    return out


def describe(before: Snapshot, root: str | Path, after: Snapshot | None = None) -> str:
    """CHANGES.md: what the tree under ``root`` changed against ``before`` (timings never count).
    ``after``: the tree's snapshot when the caller has taken it (default: taken here)."""
    after = snapshot(root) if after is None else after
    lines = ["# What the last regeneration moved", "",
             "Written by `fkopt reproduce` (or `make bench-suite`, through `fkopt report --changes-since`) "
             "from the tree before and after it ran (`fkopt/reproduce/changes.py`); "
             "timing files and figures are left out. Summary moves list the watched columns only.", ""]
    added = sorted(set(after.files) - set(before.files))
    removed = sorted(set(before.files) - set(after.files))
    if added:
        lines += ["New results: " + ", ".join(added), ""]
    if removed:
        lines += ["Results no longer produced (folders left in place): " + ", ".join(removed), ""]
    unchanged = []
    for label in sorted(set(after.files) & set(before.files)):
        old, new = before.files[label], after.files[label]
        changed = sorted(f for f in set(old) | set(new) if old.get(f) != new.get(f))
        if not changed:
            unchanged.append(label)
            continue
        lines.append(f"## {label}")
        lines.append("")
        lines.append("Files changed: " + ", ".join(f"`{f}`" for f in changed))
        moves = _summary_moves(before.summaries.get(label), after.summaries.get(label))
        if moves:
            lines.append("")
            lines += [f"- {m}" for m in moves[:MAX_ROWS]]
            if len(moves) > MAX_ROWS:
                lines.append(f"- … and {len(moves) - MAX_ROWS} more rows")
        lines.append("")
    verdicts = []
    for paper in sorted(set(before.claims) | set(after.claims)):
        verdicts += [f"- {paper}: {m}" for m in _claim_moves(before.claims.get(paper), after.claims.get(paper))]
        if paper not in before.claims and paper in after.claims:
            verdicts.append(f"- {paper}: claims.csv is new")
    if verdicts:
        lines += ["## Verdicts that changed", ""] + verdicts + [""]
    lines += [f"Unchanged (every deterministic file byte-identical): {', '.join(unchanged) if unchanged else 'none'}.",
              ""]
    return "\n".join(lines)


def agreement(before: Snapshot, root: str | Path, after: Snapshot | None = None) -> str:
    """One line for the end of ``fkopt reproduce``: how many deterministic files moved against
    the tree before it (timings never count) and whether ``fkopt check``'s cross-platform rules
    (:mod:`fkopt.run.compare`) accept the new files against the old. On the platform that made the
    stored results nothing moves; on another CPU (another SIMD width in numpy's kernels, another
    BLAS) the last digits of path-dependent runs move and the rules decide whether that is all.
    Needs a snapshot taken with ``keep``. ``after``: the tree's snapshot the caller already took
    for :func:`describe` (``fkopt reproduce`` threads the one :func:`write_changes` took, so the
    tree is hashed once at its end), default: taken here."""
    root = Path(root)
    after = snapshot(root) if after is None else after
    moved: dict[str, list[str]] = {}
    for label in sorted(set(after.files) & set(before.files)):
        old, new = before.files[label], after.files[label]
        files = sorted(f for f in set(old) | set(new) if old.get(f) != new.get(f))
        if files:
            moved[label] = files
    count = sum(len(f) for f in moved.values())
    added = len(set(after.files) - set(before.files))
    new = f" ({added} results are new)" if added else ""
    if not count:
        return "reproduce: every deterministic file is byte-identical to the stored one" + new
    if before.copies is None:
        return f"reproduce: {count} deterministic files in {len(moved)} results moved"
    store = {f"{e.paper}/{e.name}": e for e in Store(root).folders(None)}
    refused = {}
    for label, files in moved.items():
        found = compare_folders(label, before.copies / label, root / label, rules_for(store[label], ANY),
                                files=[f for f in files if (before.copies / label / f).exists()
                                       and (root / label / f).exists()])
        if found:
            refused[label] = found
    head = f"reproduce: {count} deterministic files in {len(moved)} results moved from the stored ones{new}; "
    if not refused:
        return head + ("fkopt check's cross-platform rules accept all of them (another CPU moves the last "
                       "digits of path-dependent runs: docs/reproducing.md)")
    first = next(iter(refused.values()))[0]
    return head + (f"fkopt check's cross-platform rules refuse {sum(map(len, refused.values()))} difference(s) "
                   f"in {len(refused)} results (first: {first.experiment} {first.file} {first.column}); "
                   "see CHANGES.md and run `fkopt check`")


def write_changes(root: str | Path, before: Snapshot) -> tuple[Path, Snapshot]:
    """Write CHANGES.md at the root of the regenerated tree; returns its path and the snapshot of
    the tree it compared (for :func:`agreement`, without hashing the tree again)."""
    path = Path(root) / CHANGES_FILE
    after = snapshot(root)
    text = describe(before, root, after)
    write_file_atomically(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    return path, after
