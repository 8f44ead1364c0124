"""Name -> implementation maps for mechanisms and algorithms.

Adding a mechanism or an algorithm is one new module plus one line here. Entries are
``"module:Class"`` strings imported on first use, so listing names costs nothing.
"""
from __future__ import annotations

import importlib

from .errors import FkoptError, did_you_mean

MECHANISMS: dict[str, str] = {
    "3-rps": "fkopt.mechanisms.rps3:ThreeRPS",
    "6-sps": "fkopt.mechanisms.sps6:SixSPS",
    "6-sps-cmm": "fkopt.mechanisms.sps6:SixSPSCMM",
    "3-rpupc-ups": "fkopt.mechanisms.rpupc_ups:ThreeRPUPcUPS",
    "3-ppr": "fkopt.mechanisms.ppr3:ThreePPR",
    "dh-arm": "fkopt.mechanisms.dh_arm:DHArm",
    "7dof-arm": "fkopt.mechanisms.dh_arm:SevenDofArm",
}

ALGORITHMS: dict[str, str] = {
    "abc": "fkopt.algorithms.abc:ABC",
    "gabc": "fkopt.algorithms.gabc:GABC",
    "aco": "fkopt.algorithms.aco:ACO",
    "pso": "fkopt.algorithms.pso:PSO",
    "pabc": "fkopt.algorithms.pabc:PABC",
    "nr": "fkopt.algorithms.nr:NR",
    "lm": "fkopt.algorithms.lm:LM",
    "dls": "fkopt.algorithms.dls:DLS",
    "abc+lm": "fkopt.algorithms.hybrid:ABCLM",
    "gabc+lm": "fkopt.algorithms.hybrid:GABCLM",
    "pso+lm": "fkopt.algorithms.hybrid:PSOLM",
}


def _load(table: dict[str, str], kind: str, name: str):
    try:
        target = table[name]
    except KeyError:
        raise FkoptError(f"unknown {kind} '{name}'; allowed: {did_you_mean(name, table)}") from None
    module, cls = target.split(":")
    return getattr(importlib.import_module(module), cls)


def mechanism_class(name: str):
    return _load(MECHANISMS, "mechanism", name)


def algorithm_class(name: str):
    return _load(ALGORITHMS, "algorithm", name)
