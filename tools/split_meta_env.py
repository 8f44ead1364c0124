"""One-off migration of a stored results tree to the meta.json / env.json split (issue 10).

Older fkopt wrote the library versions and the platform into every meta.json, so a rerun in a
fresh venv changed it. This script moves them into env.json beside it, adds the SHA-256 of every
deterministic CSV to meta.json (``files``; ``fkopt check`` verifies them) and rewrites meta.json
in the one layout fkopt writes (sorted keys, indent 2). It recomputes nothing.

The platform fingerprint of env.json is this machine's when the stored library versions equal
the installed ones (the results were computed here); otherwise the BLAS build and CPU are
recorded as unknown, so ``fkopt check`` compares such results by its tolerances.

    python tools/split_meta_env.py results
"""
import json
import sys
from pathlib import Path

from fkopt.compare import file_digests
from fkopt.files import write_json
from fkopt.provenance import ENV_FILE, fingerprint, library_versions

MOVED = ("fkopt_version", "libraries", "platform")


def migrate(folder: Path) -> bool:
    meta_path = folder / "meta.json"
    meta = json.loads(meta_path.read_text())
    moved = {k: meta.pop(k) for k in MOVED if k in meta}
    libs = moved.get("libraries", {})
    here = fingerprint()
    same = all(libs.get(k) == library_versions().get(k) for k in ("python", "numpy", "scipy", "pandas"))
    fp = dict(here) if same else {"python": libs.get("python", "?"), "numpy": libs.get("numpy", "?"),
                                   "scipy": libs.get("scipy", "?"), "pandas": libs.get("pandas", "?"),
                                   "blas": "unknown", "machine": moved.get("platform", {}).get("machine", "?"),
                                   "cpu": "unknown"}
    env = {"fkopt_version": moved.get("fkopt_version", "unknown"), "libraries": libs,
           "platform": {**moved.get("platform", {}), "cpu": fp["cpu"]}, "fingerprint": fp}
    meta["files"] = file_digests(folder)
    write_json(meta_path, meta)
    if not (folder / ENV_FILE).exists():
        write_json(folder / ENV_FILE, env)
    return bool(moved)


if __name__ == "__main__":
    root = Path(sys.argv[1] if len(sys.argv) > 1 else "results")
    for meta in sorted(root.glob("*/*/meta.json")):
        print(("migrated " if migrate(meta.parent) else "digests  ") + str(meta.parent))
