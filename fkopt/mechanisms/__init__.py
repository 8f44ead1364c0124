"""Mechanisms: geometry, pose/joint variables with units, search bounds and closed-form maps.

One module per mechanism, listed by name in :mod:`fkopt.mechanisms.catalog`.
"""
from fkopt.mechanisms.base import Mechanism, ParallelMechanism, SerialMechanism

__all__ = ["Mechanism", "ParallelMechanism", "SerialMechanism"]
