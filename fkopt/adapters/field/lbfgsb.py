"""scipy's L-BFGS-B (Byrd, Lu, Nocedal and Zhu 1995; ``scipy.optimize.minimize``) from random
starts on :func:`fkopt.adapters.field.pose_objective`: a bounded quasi-Newton method that sees
only the objective (gradients by scipy's forward differences, n + 1 evaluations each).

Settings: ``bounds`` = the joint limits, ``maxiter`` = 200 per start, ``ftol`` = 0 and ``gtol``
= 1e-14 (stop on the gradient, not on a small relative decrease, so it can reach FTARGET),
``eps`` = 1e-8 (scipy's difference step), random starts from the wrapper's generator until
FTARGET or the deadline; a start past the deadline is stopped by a callback raising
``StopIteration`` (scipy >= 1.11 returns the point reached).
"""
from __future__ import annotations

import time

import numpy as np

from fkopt.adapters.field import BlackBoxIK


class LBFGSB(BlackBoxIK):
    name = "scipy-lbfgsb"
    package = "scipy"
    MAXITER, GTOL, EPS = 200, 1e-14, 1e-8

    def __init__(self, arm, *, timeout, rng):
        super().__init__(arm, timeout=timeout, rng=rng)
        import scipy
        from scipy.optimize import minimize
        self._minimize = minimize
        self.settings.update(version=scipy.__version__, maxiter=self.MAXITER, ftol=0, gtol=self.GTOL, eps=self.EPS,
                             gradient="scipy forward differences")

    def search(self, f, x0, deadline):
        def stop(intermediate_result):
            if intermediate_result.fun <= self.FTARGET or time.perf_counter() > deadline:
                raise StopIteration
        res = self._minimize(lambda x: float(f(x)[0]), x0, method="L-BFGS-B",
                             bounds=list(zip(self.lo_rad, self.hi_rad)), callback=stop,
                             options={"maxiter": self.MAXITER, "ftol": 0.0, "gtol": self.GTOL, "eps": self.EPS})
        return np.asarray(res.x), float(res.fun)
