"""The IOHprofiler data format -- what the ``ioh`` package's ``ioh.logger.Analyzer`` writes and
IOHanalyzer and iohinspector read: its constants and a reader. Below both of its users:
:mod:`fkopt.export` writes it, :mod:`fkopt.kinbench.outside` imports other tools' runs with it.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

#: The ioh release whose ``ioh.logger.Analyzer`` output the index layout mirrors.
IOH_VERSION = "0.4.2"
#: The columns of a ``.dat`` file.
ATTRIBUTES = ["evaluations", "raw_y"]


def read_ioh(folder: Path) -> dict:
    """Read IOHprofiler data (the ``ioh`` Analyzer logger's layout, which :func:`fkopt.export.ioh_export` writes):
    ``{(algorithm, function_name, instance): [(array of (evaluations, y) rows, run info), ...]}``.
    What :mod:`fkopt.kinbench.outside` imports results of other tools with; fkopt's own tests read
    the export with iohinspector instead."""
    out: dict = {}
    for index_file in sorted(Path(folder).glob("*/IOHprofiler_f*.json")):
        index = json.loads(index_file.read_text(encoding="utf-8"))
        for sc in index["scenarios"]:
            blocks, current = [], None
            for line in (index_file.parent / sc["path"]).read_text(encoding="utf-8").splitlines():
                if line.startswith("evaluations"):
                    current = []
                    blocks.append(current)
                elif line.strip():
                    e, y = line.split()[:2]
                    current.append((int(e), float(y)))
            if len(blocks) != len(sc["runs"]):
                raise ValueError(f"{index_file}: {len(sc['runs'])} runs indexed, {len(blocks)} in the .dat")
            for run, block in zip(sc["runs"], blocks):
                key = (index["algorithm"]["name"], index["function_name"], run["instance"])
                out.setdefault(key, []).append((np.array(block, dtype=float), run))
    return out
