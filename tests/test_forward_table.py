"""fkopt.forward's start table (joint space, :func:`fkopt.kinematics.start_tables._forward_table`): built the
same way every time, it solves Dietmaier's 6-6 platform where the centre start and the
deterministic restarts do not, and its answers are checked by the mechanism's own closed form
and by scipy's least_squares run from the table's start (an independent solver)."""
import numpy as np
import pytest

import fkopt
from fkopt.kinematics import solvers as kinematics
from fkopt.errors import FkoptError


def dietmaier_queries(n, seed=7):
    m = fkopt.mechanism("6-sps")
    b = m.bounds
    X = b[:, 0] + np.random.default_rng(seed).random((n, 6)) * (b[:, 1] - b[:, 0])
    return m, X, m.ik(X)


def test_start_table_is_deterministic_and_cached_by_geometry():
    m = fkopt.mechanism("6-sps")
    a = kinematics._forward_table(m, 256)
    assert kinematics._forward_table(fkopt.mechanism("6-sps"), 256) is a      # a mechanism built again finds it
    for key in [k for k in kinematics._TABLES if k[0] == "forward" and k[4] == 256]:
        del kinematics._TABLES[key]
    b = kinematics._forward_table(m, 256)
    assert b is not a
    for k in ("pose", "joints", "features", "feature_scale"):
        np.testing.assert_array_equal(a[k], b[k])
    assert np.all(m.in_bounds(a["pose"])) and len(a["pose"]) == 256
    np.testing.assert_array_equal(a["joints"], m.ik(a["pose"]))
    # another geometry (the CMM) gets its own table
    assert kinematics._forward_table(fkopt.mechanism("6-sps-cmm"), 256) is not a


def test_table_solves_what_the_centre_start_and_restarts_do_not():
    m, X, L = dietmaier_queries(12)
    old = fkopt.forward(m, L, tol=1e-10, table=0, global_search=False)
    new = fkopt.forward(m, L, tol=1e-10, global_search=False)
    assert new.solved.all() and (new.solved & ~old.solved).sum() >= 2
    assert (old.stage == 0).sum() <= 2                                     # the centre start alone solves few
    # rows the centre start solves keep their answers (the table comes after it)
    at_centre = old.stage == 0
    np.testing.assert_array_equal(new.pose[at_centre], old.pose[at_centre])
    # outside check: the answers' legs by the closed form are the query's
    err = np.abs(m.ik(new.pose[new.solved]) - L[new.solved]).max(axis=-1)
    assert np.all(err <= 1e-10)
    # one row alone (the scalar path) gives the batch's verdicts
    one = [bool(fkopt.forward(m, L[i], tol=1e-10, global_search=False).solved) for i in range(4)]
    assert one == new.solved[:4].tolist()


def test_table_start_agrees_with_scipy_least_squares():
    """scipy's least_squares (trust region, its own finite-difference Jacobian) from the table's
    nearest pose reaches the pose fkopt.forward reports from that start."""
    from scipy.optimize import least_squares

    from fkopt.kinbench.physical import fk_verdicts
    m, X, L = dietmaier_queries(12, seed=3)
    tab = kinematics._forward_table(m, kinematics.FORWARD_TABLE)
    near = kinematics._nearest(tab, kinematics._joint_features(tab, L), 1)[:, 0]
    agreed = 0
    for i in range(len(L)):
        start = tab["pose"][near[i]]
        ours = fkopt.forward(m, L[i], tol=1e-10, start=start, table=0, global_search=False)
        ls = least_squares(lambda x: m.ik(x[None])[0] - L[i], start, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
        if ours.solved and ours.stage == 0 and np.abs(ls.fun).max() < 1e-10:
            # the same pose as frames (Euler angles may differ by turns); kinbench's pose errors
            v = fk_verdicts(m, ls.x[None], ours.pose[None], L[i:i + 1])
            agreed += bool(v["position_m"][0] < 1e-6 and v["rotation_rad"][0] < 1e-6)
    assert agreed >= 4                                   # measured: 5 of the 6 rows both solve from that start


def test_exact_solver_keeps_the_stored_setting():
    from fkopt.kinematics.as_algorithms import ForwardParams
    assert ForwardParams().table == 0


def test_table_bad_input():
    with pytest.raises(FkoptError, match="table"):
        fkopt.forward("6-sps", kinematics.np.ones(6), table=-1)


def test_a_row_keeps_the_likeliest_of_its_candidate_solutions():
    """The first ``candidates`` table starts all run; the answer is the solution among theirs with
    the smallest |det J| (the likeliest mode for a pose drawn uniformly in the bounds), recomputed
    here from each start alone and the mechanism's own Jacobian."""
    m, X, L = dietmaier_queries(3, seed=5)
    tab = kinematics._forward_table(m, kinematics.FORWARD_TABLE)
    near = kinematics._nearest(tab, kinematics._joint_features(tab, L), 4)
    compared = 0
    for i in range(len(L)):
        got = fkopt.forward(m, L[i], tol=1e-10, candidates=4, global_search=False)
        if got.stage != 1:
            continue
        alone = [fkopt.forward(m, L[i], tol=1e-10, start=tab["pose"][j], table=0, global_search=False)
                 for j in near[i]]
        sols = [a.pose for a in alone if a.solved and a.stage == 0]
        if not sols:
            continue
        vol = [abs(np.linalg.det(m.jacobian(p[None])[0])) for p in sols]
        np.testing.assert_array_equal(got.pose, sols[int(np.argmin(vol))])
        compared += len(sols) > 1
    assert compared >= 1
    first = fkopt.forward(m, L, tol=1e-10, candidates=1, global_search=False)
    assert first.solved.all()


def test_the_exact_solver_takes_the_table_when_a_config_asks():
    """``params: {table: 4096}`` gives the exact solver fkopt.forward's own default answers; a
    negative size is one line naming the parameter."""
    from fkopt.kinematics.as_algorithms import Exact, row_seeds
    from fkopt.problems import fk_problem
    from fkopt.solve import solve
    from fkopt.numerics.streams import RunStreams
    m, X, L = dietmaier_queries(2, seed=9)
    res = solve(fk_problem(m, L), Exact(table=kinematics.FORWARD_TABLE, global_search=False), population=20,
                iterations=2, runs=1, seed=[1, 2])
    seeds = row_seeds(RunStreams([1, 2], [0, 0]))
    for c in range(2):
        ref = fkopt.forward(m, L[c], seed=seeds[c], global_search=False)
        np.testing.assert_array_equal(res.x[c, 0], ref.pose)
    with pytest.raises(FkoptError, match="parameter 'table'"):
        Exact(table=-1)
