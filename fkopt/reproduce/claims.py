"""Claims of a paper, judged against fkopt's stored results."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

HELD, NOT_HELD, NOT_CHECKABLE = "held", "not held", "not checkable"


@dataclass
class Claim:
    text: str          # the paper's claim, in its own terms
    verdict: str       # held / not held / not checkable
    evidence: str      # fkopt's numbers that decide it

    def __post_init__(self):
        assert self.verdict in (HELD, NOT_HELD, NOT_CHECKABLE), self.verdict


def verdict(ok) -> str:
    return HELD if bool(ok) else NOT_HELD


def missing(text: str, what: str) -> Claim:
    return Claim(text, NOT_CHECKABLE, f"no stored result for {what}")


def g(x, digits: int = 3) -> str:
    """Compact number formatting for evidence strings."""
    if x is None or (isinstance(x, float) and np.isnan(x)):
        return "n/a"
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    return f"{x:.{digits}g}"
