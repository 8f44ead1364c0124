"""fkopt's numerics, once each: serial-chain kinematics, the damped least-squares step and
joint-limit handling of ``fkopt.inverse``, its options, and the compiled fast path.

* :mod:`.chain` -- a serial chain as arrays (fixed transforms and joints about/along axes,
  possibly mimic-coupled): DH tables, URDF chains and MJCF bodies all reduce to it; FK and the
  geometric frame Jacobian of one configuration on Python floats (the reference).
* :mod:`.damped_least_squares` -- the damped least-squares step d = J^T (J J^T + mu I)^{-1} (-r) by
  Cholesky on Python floats, the saturation of joint limits in the null space, and the candidate
  search of one pose that :mod:`.restart_loop` repeats.
* :mod:`.restart_loop` -- the one restart loop (after roboticstoolbox's ``IKSolver._solve``): solvers
  supply their starts, a local search and a stopping test.
* :mod:`.rotations` -- every rotation helper, once (batched, stacked and on Python floats).
* :mod:`.options` -- :class:`InverseOptions`, the documented options of ``fkopt.inverse``.
* :mod:`.compiled` -- the same kernels compiled by numba (imported lazily, only when first used;
  cached on disk); :mod:`.compiled_ik` the one-pose IK loop (restarts included) on them,
  :mod:`.compiled_branches` every IK solution of a pose and paths.
* :mod:`.jit` -- numba's ``njit`` with a cache an unreadable file cannot break (set aside and
  rebuilt); :mod:`.notice` -- the one-line, once-per-process notices about the path.
* :mod:`.path` -- which path runs (``FKOPT_NUMERICS=numpy`` forces the numpy/Python reference)
  and what ``env.json`` records about it.
"""
from fkopt.numerics.options import InverseOptions  # noqa: F401
