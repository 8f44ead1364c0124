"""Options of ``fkopt.inverse`` (documented in :func:`fkopt.kinematics.solvers.inverse`)."""
from __future__ import annotations

import math
import numbers
from dataclasses import asdict, dataclass, fields

from fkopt.errors import FkoptError

#: (option, smallest allowed value) of the integer options; the rest are numbers or flags.
_INTEGERS = {"restarts": 0, "starts": 1, "iterations": 0, "fill": 1, "table": 0, "neighbours": 0, "tail": 1}
#: Float options that must be positive (``orientation_scale`` too, unless None).
_POSITIVE = ("damping", "step_cap", "down", "up")


@dataclass(frozen=True)
class InverseOptions:
    """``fkopt.inverse``'s keyword options with their defaults; ``fkopt.inverse(arm, poses,
    options=InverseOptions(restarts=50))`` equals ``fkopt.inverse(arm, poses, restarts=50)``.
    ``compiled``: None (default path, see :mod:`fkopt.numerics.path`), True or False.
    :meth:`validated` checks them (``fkopt.InverseSolver`` does so once, when it is made)."""

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

    def validated(self) -> InverseOptions:
        """These options when every one is of its type and range, else FkoptError naming the
        first bad one and what it allows."""
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name in _INTEGERS:
                low = _INTEGERS[f.name]
                if isinstance(v, bool) or not (isinstance(v, numbers.Integral) or isinstance(v, float) and v.is_integer()) \
                        or v < low:
                    raise FkoptError(f"inverse options {f.name}: expected an integer >= {low}, got {v!r}")
            elif f.name in ("exact_rotation",):
                if not isinstance(v, (bool, numbers.Integral)) or v not in (0, 1):
                    raise FkoptError(f"inverse options {f.name}: expected true or false, got {v!r}")
            elif f.name == "compiled":
                if v not in (None, True, False) or not isinstance(v, (bool, type(None))):
                    raise FkoptError(f"inverse options compiled: expected None, true or false, got {v!r}")
            else:
                ok = not isinstance(v, bool) and isinstance(v, numbers.Real) and math.isfinite(v)
                if f.name == "orientation_scale":
                    ok = v is None or (ok and v > 0)
                elif f.name == "rest":
                    ok = ok and v >= 0
                else:
                    ok = ok and v > 0
                if not ok:
                    allowed = {"orientation_scale": "None or a number > 0", "rest": "a number >= 0"}.get(
                        f.name, "a number > 0")
                    raise FkoptError(f"inverse options {f.name}: expected {allowed}, got {v!r}")
        return self
