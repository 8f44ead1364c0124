"""Summary of the peer experiments (``peers/*.yaml``, ``make reproduce-peers``) as markdown.

:func:`peers_markdown` reads stored results only (``summary.csv``, ``runs.csv``, ``meta.json``, ``env.json``
of every ``<paper>/peers/`` folder under a results root) and says, per paper, how each
library's counterpart did beside fkopt's algorithm at the same evaluation budget. It is what
``results/peers/PEERS.md`` holds; ``fkopt.reproduce.report`` may include it as a section:
``peers_markdown(Path("results/peers"))``.

Reading rule: "same level" when the two medians of the final fitness are within a factor 10 of
each other or both below the threshold; otherwise the better one is named with the factor (or,
when one median is exactly 0, with the other's value).
Success rate is the share of runs below the threshold. Evaluations are the mean per run
(``runs.csv``), so the equal-budget claim can be checked in the table itself.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.errors import FkoptError
from fkopt.files import parse_json, read_stored, read_stored_csv

#: Which fkopt algorithm each library algorithm is the counterpart of (by name).
COUNTERPARTS = {"niapy:ArtificialBeeColonyAlgorithm": "abc", "niapy:ParticleSwarmAlgorithm": "pso",
                "pymoo:PSO": "pso"}


def _fmt(v: float) -> str:
    return "nan" if not np.isfinite(v) else f"{v:.3g}"


def _verdict(a: float, b: float, name_a: str, name_b: str, thr: float | None) -> str:
    if thr is not None and a < thr and b < thr:
        return "same level (both medians below the threshold)"
    if min(a, b) <= 0:   # one reproduced the inputs exactly: no meaningful factor
        better, worse = (name_a, b) if a <= b else (name_b, a)
        return f"{better} better: median 0 (inputs reproduced exactly) against {_fmt(worse)}"
    lo, hi = sorted([a, b])
    if hi / lo <= 10:
        return "same level (medians within a factor 10)"
    better = name_a if a < b else name_b
    return f"{better} better by a factor {hi / lo:.3g} in median final fitness"


def paper_section(folder: Path) -> str:
    meta = parse_json(read_stored(folder, "meta.json"), str(folder / "meta.json"))
    summary = read_stored_csv(folder, "summary.csv")
    config = meta["config"]
    thr = config.get("threshold")
    try:   # library versions are in env.json (fkopt.run.provenance), beside the timings
        libs = parse_json(read_stored(folder, "env.json"), "env.json").get("libraries", {})
    except (OSError, ValueError, AttributeError, FkoptError):
        libs = {}
    lines = [f"## {config.get('paper')}: {config.get('title', '')}", ""]
    used = sorted({a["name"].split(":")[0] for a in config["algorithms"] if ":" in a["name"]})
    versions = ", ".join(f"{lib} {libs.get(lib, 'version not recorded')}" for lib in used)
    lines.append(f"{config['runs']} runs per algorithm, seed {config['seed']}, threshold {thr}; "
                 f"libraries: {versions or 'none'}.")
    lines += ["", "| case | algorithm | name | median f | best f | success | mean evaluations |",
              "|---|---|---|---|---|---|---|"]
    names = {(a.get("label") or a["name"]): a["name"] for a in config["algorithms"]}
    for _, r in summary.iterrows():
        succ = r.get("success_rate", np.nan)
        lines.append(f"| {r['case']} | {r['algorithm']} | `{names.get(r['algorithm'], '')}` | "
                     f"{_fmt(r['median_fitness'])} | {_fmt(r['best_fitness'])} | "
                     f"{'' if pd.isna(succ) else f'{succ:.0%}'} | {r['mean_evaluations']:.0f} |")
    lines.append("")
    for case, df in summary.groupby("case", sort=False):
        by = {row["algorithm"]: row for _, row in df.iterrows()}
        for label, name in names.items():
            own = COUNTERPARTS.get(name)
            mine = next((lbl for lbl, n in names.items() if n == own), None)
            if own is None or mine is None or label not in by or mine not in by:
                continue
            a, b = by[mine], by[label]
            ratio = b["mean_evaluations"] / a["mean_evaluations"]
            lines.append(f"- {case}: fkopt `{mine}` vs `{name}` ({ratio:.3f}x its evaluations): "
                         + _verdict(a["median_fitness"], b["median_fitness"], f"fkopt {mine}", label, thr) + ".")
        best = df.loc[df["median_fitness"].idxmin()]
        ties = df[df["median_fitness"] == best["median_fitness"]]["algorithm"].tolist()
        lines.append(f"- {case}: lowest median final fitness {_fmt(best['median_fitness'])}: "
                     + ", ".join(f"`{t}`" for t in ties) + ".")
    lines.append("")
    return "\n".join(lines)


def peers_markdown(root: Path) -> str:
    """Markdown summary of every ``<paper>/peers/`` folder under ``root``."""
    root = Path(root)
    folders = sorted(p.parent for p in root.glob("*/peers/meta.json"))
    head = ["# Peers: fkopt's algorithms beside other libraries' at equal evaluations", "",
            "Generated by `make reproduce-peers` from `peers/*.yaml` (see `peers/README.md`). Each library "
            "run is fkopt's wrapper around the library: it counts every evaluation, stops the library at the "
            "budget and gives each run its own seed (`fkopt/adapters/base.py`).", "",
            "What it shows: where a library implements the same method (ABC, PSO), fkopt's implementation "
            "is compared with it at the same evaluation budget on the paper's own problem. Agreement "
            "within a factor 10 of the median, or both below the threshold, supports fkopt's "
            "implementation; a large gap is named below and points at a difference of the "
            "variants (inertia schedule, velocity clamp, bound handling, onlooker probabilities), "
            "which each config's comments list. Libraries without a counterpart (wu2015's ACO) "
            "give general-purpose references at the same budget. Few runs per peer (5-30): "
            "medians, not significance tests.", ""]
    if not folders:
        return "\n".join(head + ["No peer results under this folder.", ""])
    return "\n".join(head + [paper_section(f) for f in folders])


def write_peers_summary(root: Path) -> Path:
    path = Path(root) / "PEERS.md"
    path.write_text(peers_markdown(root))
    return path


if __name__ == "__main__":   # make reproduce-peers: python -m fkopt.tools.peers results/peers
    print(write_peers_summary(Path(sys.argv[1] if len(sys.argv) > 1 else "results/peers")))
