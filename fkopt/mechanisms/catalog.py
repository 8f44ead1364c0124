"""The built-in mechanisms by name (floor 0): what :mod:`fkopt.registry` resolves first, and what
:func:`fkopt.forward` / :func:`fkopt.inverse` take as a name. Adding a mechanism to fkopt is one
module in this package plus one line here (plug-ins: :mod:`fkopt.registry`)."""
from __future__ import annotations

from fkopt.mechanisms.dh_arm import DHArm, SevenDofArm
from fkopt.mechanisms.dh_chain import DHChain
from fkopt.mechanisms.mjcf import MJCFArm
from fkopt.mechanisms.ppr3 import ThreePPR
from fkopt.mechanisms.rps3 import ThreeRPS
from fkopt.mechanisms.rpupc_ups import ThreeRPUPcUPS
from fkopt.mechanisms.sps6 import SixSPS, SixSPSCMM
from fkopt.mechanisms.urdf import URDFArm

MECHANISMS: dict[str, type] = {
    "3-rps": ThreeRPS,
    "6-sps": SixSPS,
    "6-sps-cmm": SixSPSCMM,
    "3-rpupc-ups": ThreeRPUPcUPS,
    "3-ppr": ThreePPR,
    "dh-arm": DHArm,
    "7dof-arm": SevenDofArm,
    "dh-chain": DHChain,   # seeded spatial chains, n joints (kinbench v3)
    "urdf": URDFArm,
    "mjcf": MJCFArm,
}
