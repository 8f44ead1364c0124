"""Reproduction of the five source papers: run every config, write REPORT.md, check drift.

* :mod:`.store`   -- read a results tree (CSV tables and meta.json of each experiment);
* :mod:`.report`  -- ``results/REPORT.md`` (deterministic: tables beside the printed numbers,
  figures, claims held/not held, known errors of the papers), ``results/TIMING.md`` (only
  timings and time-based claims, which change on every run) and ``results/index.csv``;
* :mod:`.check`   -- rerun stored experiments from their recorded config and compare;
* one module per paper (``mao2017.py``, ...) with its notes and its claims, registered in
  :data:`PAPERS`.
"""
import importlib


PAPERS: dict[str, str] = {
    "mao2017": "fkopt.reproduce.mao2017",
    "chang2024": "fkopt.reproduce.chang2024",
    "wu2015": "fkopt.reproduce.wu2015",
    "liu2008": "fkopt.reproduce.liu2008",
    "wang7dof": "fkopt.reproduce.wang7dof",
    "assembly": "fkopt.reproduce.assembly",
    "studies": "fkopt.reproduce.studies",
}


def paper_module(key: str):
    """The module of a paper key (its notes and claims), or None for a folder that is no paper."""
    return importlib.import_module(PAPERS[key]) if key in PAPERS else None
