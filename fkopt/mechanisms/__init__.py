"""Mechanisms: geometry, pose/joint variables with units, search bounds and closed-form maps.

One module per mechanism, registered in :mod:`fkopt.registry`.
"""
from fkopt.mechanisms.base import Mechanism, ParallelMechanism, SerialMechanism

__all__ = ["Mechanism", "ParallelMechanism", "SerialMechanism"]
