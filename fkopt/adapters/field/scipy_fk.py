"""FK of parallel mechanisms by scipy's ``least_squares`` (trust-region reflective, Branch,
Coleman and Li 1999) from random starts: the outside Jacobian baseline of kinbench v3's FK
track and its clock reference.

The residual is the legs' relative error (L(x) - L) / L of the mechanism's inverse map L(x)
(:meth:`fkopt.mechanisms.base.ParallelMechanism.ik`), in the mechanism's pose units; the
Jacobian is scipy's own ('2-point' differences, so fkopt's analytic Jacobians do not help it).

Settings: ``method`` = 'trf' with the mechanism's bounds, ``x_scale`` = 'jac', ``ftol`` =
``xtol`` = ``gtol`` = 1e-15, ``max_nfev`` = 100 x dim per start, random starts uniform in the
bounds from the wrapper's generator until max |relative residual| <= 1e-12 or the wall-clock
``timeout`` (checked between starts): the board's restart loop,
:func:`fkopt.adapters.field.restarts.restart`. An answer may be another assembly mode:
:func:`fkopt.kinbench.physical.fk_verdicts` counts those apart.
"""
from __future__ import annotations

import numpy as np
from fkopt.adapters.field.restarts import restart


class LeastSquaresFK:
    """One mechanism; :meth:`solve1` takes leg lengths (n_legs,) and returns a pose (dim,) in
    the mechanism's units, or None, and whether its residual met ``ACCEPT``."""

    name = "scipy-least_squares"
    package = "scipy"
    ACCEPT, TOL, NFEV_PER_DIM = 1e-12, 1e-15, 100

    def __init__(self, mechanism, *, timeout: float, rng: np.random.Generator):
        import scipy
        from scipy.optimize import least_squares
        self.mechanism, self.timeout, self.rng = mechanism, float(timeout), rng
        self._ls = least_squares
        self.lo, self.hi = mechanism.bounds[:, 0].astype(float), mechanism.bounds[:, 1].astype(float)
        self.settings = {"timeout_s": self.timeout, "method": "trf", "x_scale": "jac", "tol": self.TOL,
                         "max_nfev": f"{self.NFEV_PER_DIM} x dim", "accept": self.ACCEPT, "jac": "2-point",
                         "version": scipy.__version__, "wall_clock_limit": "between starts",
                         "start": "uniform in bounds (wrapper's generator)"}

    def solve1(self, legs: np.ndarray) -> tuple[np.ndarray | None, bool]:
        legs = np.asarray(legs, dtype=float)
        dim = len(self.lo)

        def residual(x):
            return (self.mechanism.ik(x[None])[0] - legs) / legs

        def search(x0, deadline):
            res = self._ls(residual, x0, method="trf", bounds=(self.lo, self.hi), x_scale="jac", ftol=self.TOL,
                           xtol=self.TOL, gtol=self.TOL, max_nfev=self.NFEV_PER_DIM * dim)
            r = float(np.max(np.abs(res.fun)))
            return np.asarray(res.x), r, r <= self.ACCEPT
        x, ok, _ = restart(search, lambda: self.lo + self.rng.random(dim) * (self.hi - self.lo), self.timeout)
        return x, ok
