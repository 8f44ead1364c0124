"""Regression check of a stored study (``fkopt check`` dispatches here on ``kind: study``).

The study is rerun in this process from the config recorded in ``meta.json`` and its
``summary.csv`` is compared with the stored one by the rules of :mod:`fkopt.reproduce.check`
(fitness in log10 decades, success rates within 0.1, medians of counts relatively). Per-pose
and per-run tables are not compared (single runs, like an experiment's ``runs.csv``).
"""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import pandas as pd

from .config import StudyConfig, study_from_dict
from .reports import summary_table
from .runner import rerun_in_memory

COMPARED = ("summary.csv",)


def check_study(exp, config: StudyConfig | None = None) -> list:
    from ..reproduce.check import Mismatch, compare_tables
    config = config or study_from_dict(dict(exp.config), f"{exp.paper}/{exp.name} meta.json")
    result = rerun_in_memory(config)
    tmp = Path(tempfile.mkdtemp(prefix="fkopt-check-"))
    label = f"{exp.paper}/{exp.name}"
    try:
        summary_table(result).to_csv(tmp / "summary.csv", index=False, float_format="%.10g")
        out = []
        for file in COMPARED:
            if not exp.has(file):
                out.append(Mismatch(label, file, "-", "file", False, True, "present in both"))
                continue
            out += compare_tables(label, file, exp.table(file), pd.read_csv(tmp / file))
        return out
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
