"""CMA-ES through ``cma`` (Hansen's pycma; Hansen and Ostermeier 2001, IPOP restarts: Auger and
Hansen, CEC 2005) on :func:`fkopt.adapters.field.pose_objective`, in the joints' SI units.

Settings: ``bounds`` = the joint limits (pycma's boundary handling), per-joint initial step
``CMA_stds`` = 1/4 of each joint's range with ``sigma0`` = 1, ``ftarget`` = the wrapper's
FTARGET, ``tolfun`` = ``tolfunhist`` = 0 and ``tolx`` = 1e-14 (stop on a collapsed step, not on a
flat best), ``seed`` drawn from the wrapper's generator per start, ``verbose`` = -9. Restarts:
IPOP, the population doubles from pycma's default (4 + 3 ln n) on every restart within a query.
The whole population is evaluated in one vectorised call of fkopt's FK.

Quirks: pycma's own ``timeout`` option is checked once per iteration like the deadline here;
the deadline is the query's, over all restarts.
"""
from __future__ import annotations

import time
import warnings

import numpy as np

from fkopt.adapters.field import BlackBoxIK


class CmaES(BlackBoxIK):
    name = "cma-es"
    package = "cma"

    def __init__(self, arm, *, timeout, rng):
        super().__init__(arm, timeout=timeout, rng=rng)
        import cma
        self._cma = cma
        self._restart = 0
        self.settings.update(version=cma.__version__, restarts="IPOP (population x 2 per restart)",
                             CMA_stds="range / 4", tolx=1e-14)

    def solve1(self, T):
        self._restart = 0
        return super().solve1(T)

    def search(self, f, x0, deadline):
        n = self.arm.dof
        popsize = int((4 + int(3 * np.log(n))) * 2 ** self._restart)
        self._restart += 1
        opts = {"bounds": [self.lo_rad.tolist(), self.hi_rad.tolist()], "CMA_stds": ((self.hi_rad - self.lo_rad) / 4).tolist(),
                "ftarget": self.FTARGET, "tolfun": 0, "tolfunhist": 0, "tolx": 1e-14, "popsize": popsize,
                "seed": int(self.rng.integers(1, 2**31 - 1)), "verbose": -9, "maxiter": 10**6}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            es = self._cma.CMAEvolutionStrategy(x0.tolist(), 1.0, opts)
            while not es.stop() and time.perf_counter() < deadline:
                X = np.asarray(es.ask())
                es.tell(list(X), f(X).tolist())
        return np.asarray(es.result.xbest if es.result.xbest is not None else x0), float(es.result.fbest)
