"""Options of ``fkopt.inverse`` (documented in :func:`fkopt.kinematics.inverse`)."""
from __future__ import annotations

from dataclasses import asdict, dataclass


@dataclass(frozen=True)
class InverseOptions:
    """``fkopt.inverse``'s keyword options with their defaults; ``fkopt.inverse(arm, poses,
    options=InverseOptions(restarts=50))`` equals ``fkopt.inverse(arm, poses, restarts=50)``.
    ``compiled``: None (default path, see :mod:`fkopt.numerics.path`), True or False."""

    restarts: int = 200
    starts: int = 1
    rest: float = 0.0
    orientation_scale: float | None = None
    iterations: int = 10
    damping: float = 0.01
    step_cap: float = 2.0
    down: float = 0.1
    up: float = 10.0
    fill: int = 32
    exact_rotation: bool = False
    table: int = 4096
    neighbours: int = 32
    tail: int = 256
    compiled: bool | None = None

    def as_dict(self) -> dict:
        return asdict(self)
