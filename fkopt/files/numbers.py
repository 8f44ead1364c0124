"""The median fkopt's summaries print over the values that are not NaN (runs that never
reached the threshold are NaN in the run record)."""
from __future__ import annotations

import numpy as np


def nanmedian(a) -> float:
    """Median over the non-NaN values; NaN when there are none (no numpy warning)."""
    a = np.asarray(a, dtype=float)
    ok = ~np.isnan(a)
    return float(np.median(a[ok])) if ok.any() else float("nan")
