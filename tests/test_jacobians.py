"""Analytic Jacobians of every mechanism's closed form and of the problems' residuals, checked
against central differences at random poses (hypothesis), in the public units (degrees)."""
import numpy as np
import pytest
from hypothesis import assume, given, settings, strategies as st

import fkopt
from fkopt.algorithms.nr import jacobian_cost

PARALLEL = ["3-rps", "3-ppr", "3-rpupc-ups", "6-sps", "6-sps-cmm"]
unit = st.lists(st.floats(0.02, 0.98), min_size=7, max_size=7)


def central(fun, x, h):
    cols = []
    for j in range(len(x)):
        e = np.zeros(len(x))
        e[j] = h[j]
        cols.append((fun(x + e) - fun(x - e)) / (2 * h[j]))
    return np.stack(cols, axis=-1)


def point_in(m, u, shrink=1.0):
    b = m.bounds
    mid, half = b.mean(axis=1), 0.5 * (b[:, 1] - b[:, 0]) * shrink
    return mid + (2 * np.asarray(u[:len(b)]) - 1) * half


@pytest.mark.parametrize("name", PARALLEL)
@settings(max_examples=25, deadline=None)
@given(u=unit)
def test_parallel_jacobian_matches_differences(name, u):
    m = fkopt.mechanism(name)
    # 6-sps: full-turn angle box; stay away from the Z-Y-X singularity beta = +-90
    x = point_in(m, u, 0.4 if name == "6-sps" else 1.0)
    h = 1e-6 * (m.bounds[:, 1] - m.bounds[:, 0])
    if name.startswith("6-sps"):
        assume(m.ik(x).min() > 1e-3)             # a zero-length leg has no derivative
    J = m.jacobian(x)
    F = central(m.ik, x, h)
    assert J.shape == (len(m.joint_names), len(m.pose_names))
    np.testing.assert_allclose(J, F, atol=1e-6 * (1 + np.abs(F).max()))


@pytest.mark.parametrize("name", PARALLEL + ["7dof-arm"])
def test_jacobian_batched_like_the_map(name):
    m = fkopt.mechanism(name)
    rng = np.random.default_rng(0)
    b = m.bounds
    X = b[:, 0] + rng.random((2, 5, len(b))) * (b[:, 1] - b[:, 0])
    J = m.jacobian(X)
    assert J.shape[:2] == (2, 5)
    np.testing.assert_allclose(J[1, 3], m.jacobian(X[1, 3]), rtol=1e-12, atol=1e-12)


@settings(max_examples=25, deadline=None)
@given(u=unit)
def test_arm_frame_jacobian(u):
    m = fkopt.mechanism("7dof-arm")
    q = point_in(m, u)
    p, R, J = m.frame_jacobian(q)
    h = np.full(7, 1e-5)
    Fp = central(lambda x: m.fk(x)[:3], q, h)
    np.testing.assert_allclose(J[:3], Fp, atol=1e-6)
    # angular velocity: skew part of dR R^T
    dR = central(lambda x: m.frame_jacobian(x)[1].ravel(), q, h).reshape(3, 3, 7)
    W = np.einsum("ijk,lj->ilk", dR, R)
    np.testing.assert_allclose(J[3:], np.stack([W[2, 1], W[0, 2], W[1, 0]]), atol=1e-8)


@pytest.mark.parametrize("objective", ["paper", "geodesic"])
@settings(max_examples=20, deadline=None)
@given(u=unit, v=unit)
def test_ik_problem_jacobian(objective, u, v):
    m = fkopt.mechanism("7dof-arm")
    target = m.fk(point_in(m, v))
    if objective == "paper" and not 5 < target[4] < 175:
        return                                   # Euler rates are singular at sin(beta) = 0
    problem = fkopt.ik_problem(m, target, objective=objective)
    q = point_in(m, u)
    r = problem.residuals(q)
    if objective == "paper":
        euler = m.fk(q)[3:]
        if not 5 < euler[1] < 175 or np.any(np.abs(np.degrees(r[3:]) / problem.w_r) > 170):
            return                               # singular or next to the +-180 wrap
    else:
        if np.linalg.norm(r[3:] / problem.w_r) > 3.0:
            return                               # next to the rotation-vector cut at pi
    J = problem.jacobian(q)
    F = central(problem.residuals, q, np.full(7, 1e-5))
    np.testing.assert_allclose(J, F, atol=1e-5 * (1 + np.abs(F).max()))


def test_fk_problem_uses_the_analytic_jacobian():
    m = fkopt.mechanism("3-rpupc-ups")
    pose = np.array([25.0, 34.0, 23.0, 360.0])
    problem = fkopt.fk_problem(m, m.ik(pose))
    assert problem.has_jacobian and jacobian_cost(problem) == 1
    np.testing.assert_array_equal(problem.jacobian(pose), m.jacobian(pose))
    res = fkopt.solve(problem, "nr", x0=[20, 30, 20, 350], iterations=20)
    np.testing.assert_allclose(res.x[0], pose, atol=1e-8)


def test_arm_frame_jacobian_elementwise_path_matches_products():
    m = fkopt.mechanism("7dof-arm")
    rng = np.random.default_rng(2)
    b = m.bounds
    Q = b[:, 0] + rng.random((300, 7)) * (b[:, 1] - b[:, 0])   # >= the column path's batch size
    big = m.frame_jacobian(Q)
    small = m.frame_jacobian(Q[:50])                           # 4x4 products
    for a, c in zip(big, small):
        np.testing.assert_allclose(a[:50], c, atol=1e-9)


@pytest.mark.parametrize("name", ["6-sps", "6-sps-cmm"])
def test_sps_ik_jacobian_elementwise_path_matches(name):
    m = fkopt.mechanism(name)
    rng = np.random.default_rng(5)
    b = m.bounds
    X = b[:, 0] + rng.random((400, 6)) * (b[:, 1] - b[:, 0])   # >= the elementwise batch size
    v, J = m.ik_jacobian(X)
    v2, J2 = m.ik_jacobian(X[:40])
    np.testing.assert_allclose(v, m.ik(X), rtol=1e-14)
    np.testing.assert_allclose(v[:40], v2, rtol=1e-14)
    np.testing.assert_allclose(J[:40], J2, atol=1e-14)
