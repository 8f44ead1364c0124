"""Options of ``fkopt.inverse`` (documented in :func:`fkopt.kinematics.solvers.inverse`)."""
from __future__ import annotations

import numbers
from dataclasses import asdict, dataclass, fields

from fkopt.errors import FkoptError
from fkopt.api_bounds import check_options



@dataclass(frozen=True)
class InverseOptions:
    """``fkopt.inverse``'s keyword options with their defaults; ``fkopt.inverse(arm, poses,
    options=InverseOptions(restarts=50))`` equals ``fkopt.inverse(arm, poses, restarts=50)``.
    ``compiled``: None (default path, see :mod:`fkopt.numerics.path`), True or False. ``threads``:
    threads sharing a batch on the compiled path (None: the CPUs the process may run on; 1: the
    calling thread alone); the answers are the same for any number.
    :meth:`validated` checks them (``fkopt.InverseSolver`` does so once, when it is made)."""

    restarts: int = 200
    starts: int = 1
    rest: float = 0.0
    orientation_scale: float | None = None
    iterations: int = 20
    damping: float = 5e-4
    step_cap: float = 2.0
    down: float = 0.1
    up: float = 10.0
    stall: float = 0.5
    fill: int = 32
    exact_rotation: bool = False
    table: int = 4096
    neighbours: int = 32
    tail: int = 256
    compiled: bool | None = None
    threads: int | None = None

    def as_dict(self) -> dict:
        return asdict(self)

    def validated(self) -> InverseOptions:
        """These options when every one is of its type and range, else FkoptError naming the
        first bad one and what it allows; the ranges, upper bounds included, are
        :mod:`fkopt.api_bounds`'s (``table`` at most 1,000,000: its memory)."""
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name in ("exact_rotation",):
                if not isinstance(v, (bool, numbers.Integral)) or v not in (0, 1):
                    raise FkoptError(f"inverse options {f.name}: expected true or false, got {v!r}")
            elif f.name == "threads" and v is None:
                pass
            elif f.name == "compiled":
                if v not in (None, True, False) or not isinstance(v, (bool, type(None))):
                    raise FkoptError(f"inverse options compiled: expected None, true or false, got {v!r}")
            else:
                check_options("inverse options", **{f.name: v})
        return self
