"""3-RPUPc-UPS (chang2024), 3-PPR (wu2015), DH arms / 7-DOF arm (wang7dof) and IKProblem."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

import fkopt
from fkopt.numerics import rotations
from fkopt.mechanisms.dh_arm import DHArm, SevenDofArm
from fkopt.mechanisms.ppr3 import ThreePPR
from fkopt.mechanisms.rpupc_ups import ThreeRPUPcUPS

angle = st.floats(-179.0, 179.0)


def soa(M):
    """(..., 3, 3) array -> structure-of-arrays matrix."""
    M = np.asarray(M)
    return tuple(tuple(M[..., i, j] for j in range(3)) for i in range(3))


def random_in(bounds, n, seed):
    rng = np.random.default_rng(seed)
    return rng.uniform(bounds[:, 0], bounds[:, 1], size=(n, len(bounds)))


def lsq(problem, x0):
    b = problem.bounds
    return least_squares(problem.residuals, x0, bounds=(b[:, 0], b[:, 1]),
                         xtol=1e-15, ftol=1e-15, gtol=1e-15).x


# -- registry -------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["3-rpupc-ups", "3-ppr", "dh-arm", "7dof-arm"])
def test_registered(name):
    m = fkopt.mechanism(name)
    assert m.name == name
    assert m.bounds.shape == (len(m.unknown_names), 2)


# -- chang2024: 3RPUPc-UPS --------------------------------------------------------------------
def reference_rpupc(pose, R=120.0, c=60.0):
    """SPEC.md's reconstruction written with matrices and cross products (independent check)."""
    a, b, g = np.radians(pose[:3])
    z = pose[3]

    def rx(t):
        return np.array([[1, 0, 0], [0, np.cos(t), -np.sin(t)], [0, np.sin(t), np.cos(t)]])

    def ry(t):
        return np.array([[np.cos(t), 0, np.sin(t)], [0, 1, 0], [-np.sin(t), 0, np.cos(t)]])

    def rz(t):
        return np.array([[np.cos(t), -np.sin(t), 0], [np.sin(t), np.cos(t), 0], [0, 0, 1]])

    Rp = rx(-a) @ ry(-b) @ rz(g)
    n = Rp[:, 2]
    Q = np.array([0.0, 0.0, z])
    u = np.cross([0, 1, 0], n)
    u = u / np.linalg.norm(u) * np.sign(u[0])
    v = np.cross(n, [1, 0, 0])
    v = v / np.linalg.norm(v) * -np.sign(v[1])
    B = np.array([[-R, 0, 0], [0, -R, 0], [R, 0, 0], [0, R, 0]])
    C = [Q - c * u, Q + c * v, Q + c * u]
    legs = [np.linalg.norm(Ci - Bi) for Ci, Bi in zip(C, B)]
    d4 = Q + Rp @ [0, c, 0] - B[3]
    return np.array([*legs, np.degrees(np.arctan2(d4[0], -d4[1]))])


def test_chang2024_printed_case():
    m = fkopt.mechanism("3-rpupc-ups")
    assert m.reconstruction and m.paper == "chang2024"
    assert m.joint_units == ("mm", "mm", "mm", "deg")
    out = m.ik([25, 34, 23, 360])
    np.testing.assert_allclose(out[:3], [332.048, 390.904, 402.294], atol=5e-4)
    assert abs(out[3] - (-14.4389)) < 5e-5
    np.testing.assert_allclose(out, [332.04835, 390.90443, 402.29361, -14.43892], atol=5e-6)
    assert m.in_bounds([25, 34, 23, 360])


@settings(max_examples=40, deadline=None)
@given(st.floats(-45, 45), st.floats(-45, 45), st.floats(-45, 45), st.floats(300, 420))
def test_rpupc_matches_matrix_reference(a, b, g, z):
    pose = np.array([a, b, g, z])
    np.testing.assert_allclose(ThreeRPUPcUPS().ik(pose), reference_rpupc(pose), rtol=0, atol=1e-9)


def test_rpupc_geometry_override_and_batches():
    m = fkopt.mechanism("3-rpupc-ups", R=150, c=50)
    pose = np.array([10.0, -5.0, 20.0, 350.0])
    np.testing.assert_allclose(m.ik(pose), reference_rpupc(pose, R=150, c=50), atol=1e-9)
    poses = random_in(m.bounds, 12, 1).reshape(3, 4, 4)
    batch = m.ik(poses)
    assert batch.shape == (3, 4, 4)
    assert np.array_equal(batch[1, 2], m.ik(poses[1, 2]))   # bit-identical whatever the batch
    with pytest.raises(fkopt.FkoptError, match="geometry"):
        fkopt.mechanism("3-rpupc-ups", r=1)


def test_rpupc_fk_round_trip_least_squares():
    # From the centre of the box, a local solver recovers every pose: no second solution nearby.
    m = fkopt.mechanism("3-rpupc-ups")
    for pose in random_in(m.bounds, 25, 2):
        problem = fkopt.fk_problem(m, m.ik(pose))
        x = lsq(problem, m.bounds.mean(axis=1))
        np.testing.assert_allclose(x, pose, atol=1e-6)


def test_rpupc_fk_by_gabc_printed_case():
    m = fkopt.mechanism("3-rpupc-ups")
    problem = fkopt.fk_problem(m, [332.04835248, 390.90443432, 402.29360866, -14.43891775])
    result = fkopt.solve(problem, "gabc", population=20, iterations=400, runs=3, seed=0)
    np.testing.assert_allclose(result.x[result.best_run], [25, 34, 23, 360], atol=1e-3)


def test_rpupc_delta_residual_wraps():
    m = fkopt.mechanism("3-rpupc-ups")
    joints = m.ik([0, 0, 0, 360])
    joints[3] += 360.0          # the same angle, one turn later
    assert fkopt.fk_problem(m, joints).fitness([0, 0, 0, 360]) < 1e-20


# -- wu2015: planar 3-PPR -----------------------------------------------------------------------
def test_wu2015_printed_case():
    m = fkopt.mechanism("3-ppr")
    assert m.reconstruction and m.paper == "wu2015"
    np.testing.assert_allclose(m.ik([20, 30, 15]), [-14.8355, 65.3984, 70.1170], atol=1e-4)
    np.testing.assert_allclose(m.bounds, [[-60, 60], [-60, 60], [-24, 24]])


def test_ppr_printed_formula_and_override():
    g = dict(r_F=30.0, phi1=200.0, phi2=320.0, phi3=80.0, D1x0=1.0, D2x0=-2.0)
    m = fkopt.mechanism("3-ppr", **g)
    x, y, th = 7.0, -3.0, 11.0
    F = [g["r_F"] * np.array([np.cos(np.radians(p)), np.sin(np.radians(p))]) for p in (200, 320, 80)]
    c, s = np.cos(np.radians(th)), np.sin(np.radians(th))
    expected = [F[0][0] * c - F[0][1] * s + x - 1.0, F[1][0] * c - F[1][1] * s + x + 2.0,
                F[2][0] * s + F[2][1] * c + y]
    np.testing.assert_allclose(m.ik([x, y, th]), expected, atol=1e-12)


def test_ppr_two_branches_in_workspace():
    # The reconstructed geometry has F1y = F2y: theta and -theta give the same inputs.
    m = fkopt.mechanism("3-ppr")
    joints = m.ik([20, 30, 15])
    branches = m.fk_exact(joints)
    assert branches.shape == (2, 3)
    np.testing.assert_allclose(branches[1], [20, 30, 15], atol=1e-9)
    np.testing.assert_allclose(branches[0], [20 + 41.5322 * np.sin(np.radians(15)), 30, -15], atol=1e-9)
    assert m.in_bounds(branches).all()
    np.testing.assert_allclose(m.ik(branches), [joints, joints], atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(st.floats(-60, 60), st.floats(-60, 60), st.floats(-24, 24).filter(lambda t: abs(t) > 0.01),
       st.floats(15, 60), st.floats(180, 240), st.floats(300, 360), st.floats(60, 120))
def test_ppr_fk_exact_inverts_ik(x, y, th, r_F, p1, p2, p3):
    m = ThreePPR(r_F=r_F, phi1=p1, phi2=p2, phi3=p3)
    pose = np.array([x, y, th])
    branches = m.fk_exact(m.ik(pose))
    err = np.abs(branches - pose).max(axis=-1)
    assert err.min() < 1e-7
    np.testing.assert_allclose(m.ik(branches), np.stack([m.ik(pose)] * 2), atol=1e-7)


def test_ppr_fk_exact_batches_and_no_solution():
    m = fkopt.mechanism("3-ppr")
    poses = random_in(m.bounds, 6, 3).reshape(2, 3, 3)
    out = m.fk_exact(m.ik(poses))
    assert out.shape == (2, 3, 2, 3)
    assert np.isnan(m.fk_exact([100.0, -100.0, 0.0])).all()   # |d1 - d2| too large


def test_ppr_fk_round_trip_least_squares():
    # Near theta = 0 the two branches meet (singular Jacobian) and a local solver may cross to
    # the mirror pose: the answer must be one of fk_exact's branches, and it is the original
    # pose whenever it started on the original's side, well away from the fold.
    m = fkopt.mechanism("3-ppr")
    for pose in random_in(m.bounds, 20, 4):
        problem = fkopt.fk_problem(m, m.ik(pose))
        start = np.clip(pose * np.array([1.0, 1.0, 1.3]) + np.array([5.0, -5.0, 0.0]),
                        m.bounds[:, 0], m.bounds[:, 1])
        x = lsq(problem, start)
        branches = m.fk_exact(problem.joints)
        assert np.abs(branches - x).max(axis=-1).min() < 1e-6
        if abs(pose[2]) > 5:
            np.testing.assert_allclose(x, pose, atol=1e-7)


def test_ppr_gabc_lands_on_a_branch():
    m = fkopt.mechanism("3-ppr")
    problem = fkopt.fk_problem(m, m.ik([20, 30, 15]))
    result = fkopt.solve(problem, "gabc", population=20, iterations=400, runs=3, seed=0)
    branches = m.fk_exact(problem.joints)
    for x in result.x:
        assert np.abs(branches - x).max(axis=-1).min() < 1.0


# -- wang7dof: DH arms --------------------------------------------------------------------------
def reference_dh(q, a, alpha, d, offset=None):
    T = np.eye(4)
    offset = np.zeros(len(a)) if offset is None else offset
    for qi, ai, al, di in zip(np.radians(np.asarray(q) + offset), a, np.radians(alpha), d):
        ct, st_, ca, sa = np.cos(qi), np.sin(qi), np.cos(al), np.sin(al)
        T = T @ np.array([[ct, -st_ * ca, st_ * sa, ai * ct], [st_, ct * ca, -ct * sa, ai * st_],
                          [0, sa, ca, di], [0, 0, 0, 1]])
    return T


WANG = dict(a=[0, 200, 250, 300, 200, 200, 100], alpha=[-90, 90, -90, 90, -90, 0, 0],
            d=[500, 0, 0, 0, 0, 0, 50])


def test_wang7dof_printed_target():
    m = fkopt.mechanism("7dof-arm")
    assert m.paper == "wang7dof"
    assert m.joint_names == tuple(f"q{i}" for i in range(1, 8))
    assert m.pose_names == ("x", "y", "z", "alpha", "beta", "gamma")
    np.testing.assert_allclose(m.bounds, [(-180, 180), (-90, 30), (-90, 120), (-90, 90), (-90, 90),
                                          (-90, 90), (-30, 90)])
    pose = m.fk([45, 0, 45, 0, 45, 0, 0])
    np.testing.assert_allclose(pose[:3], [-247.4874, 1009.6194, 500.0000], atol=1e-4)
    np.testing.assert_allclose(pose[3:], [-135, 90, -90], atol=1e-9)


@settings(max_examples=30, deadline=None)
@given(st.lists(angle, min_size=7, max_size=7))
def test_dh_matches_matrix_product(q):
    m = SevenDofArm()
    T = reference_dh(q, **WANG)
    np.testing.assert_allclose(m.fk_matrix(q), T, atol=1e-9)
    pose = m.fk(q)
    np.testing.assert_allclose(pose[:3], T[:3, 3], atol=1e-9)
    if np.sin(np.radians(pose[4])) > 1e-3:       # Euler angles describe R away from sin(beta) = 0
        R = rotations.to_array(rotations.zyz(*np.radians(pose[3:])))
        np.testing.assert_allclose(R, T[:3, :3], atol=1e-9)


def test_dh_batches_are_bit_identical():
    m = fkopt.mechanism("7dof-arm")
    q = random_in(m.bounds, 24, 5).reshape(4, 6, 7)
    batch = m.fk(q)
    assert batch.shape == (4, 6, 6) and m.fk_matrix(q).shape == (4, 6, 4, 4)
    assert np.array_equal(batch[2, 3], m.fk(q[2, 3]))


def test_dh_arm_from_lists():
    g = dict(a=[100, 80, 30], alpha=[90, 0, 0], d=[50, 0, 0], theta_offset=[0, 90, 0],
             limits=[[-170, 170], [-90, 90], [-120, 120]])
    m = fkopt.mechanism("dh-arm", **g)
    assert m.joint_names == ("q1", "q2", "q3") and len(m.pose_names) == 6
    np.testing.assert_allclose(m.bounds, g["limits"])
    q = [10.0, -20.0, 30.0]
    T = reference_dh(q, g["a"], g["alpha"], g["d"], np.array(g["theta_offset"], float))
    np.testing.assert_allclose(m.fk_matrix(q), T, atol=1e-9)
    # A 1-joint arm and a bounds override work too.
    one = fkopt.mechanism("dh-arm", a=[10], alpha=[0], d=[0], limits=[[-90, 90]], bounds={"q1": [0, 45]})
    np.testing.assert_allclose(one.bounds, [[0, 45]])
    np.testing.assert_allclose(one.fk([90])[:3], [0, 10, 0], atol=1e-12)
    assert fkopt.mechanism("7dof-arm").joint_names == DHArm.joint_names   # class default untouched


@pytest.mark.parametrize("bad, message", [
    (dict(a=[], alpha=[], d=[], limits=[]), "at least 1 joint"),
    (dict(a=[1, 2], alpha=[0], d=[0, 0], limits=[[0, 1], [0, 1]]), "equal lengths.*alpha=1"),
    (dict(a=[1], alpha=[0], d=[0], limits=[[0, 1]], theta_offset=[0, 0]), "equal lengths.*theta_offset=2"),
    (dict(a=[1], alpha=[0], d=[0], limits=[[5, 5]]), r"limits\[0\].*lower 5 must be below upper 5"),
    (dict(a=[1], alpha=[0], d=[0], limits=[[0, 1]], link=[2]), "link"),
    (dict(a=["x"], alpha=[0], d=[0], limits=[[0, 1]]), r"geometry\.a: needs numbers, got the text 'x'"),
])
def test_malformed_dh_tables(bad, message):
    with pytest.raises(fkopt.FkoptError, match=message) as err:
        fkopt.mechanism("dh-arm", **bad)
    assert "\n" not in str(err.value) and "Value error" not in str(err.value)


# -- IKProblem --------------------------------------------------------------------------------
Q_TRUE = np.array([45.0, 0.0, 45.0, 0.0, 45.0, 0.0, 0.0])


@pytest.mark.parametrize("objective", ["paper", "geodesic"])
def test_ik_fitness_zero_at_truth_positive_elsewhere(objective):
    m = fkopt.mechanism("7dof-arm")
    problem = fkopt.ik_problem(m, m.fk(Q_TRUE), objective=objective)
    assert problem.objective == objective and problem.dim == 7
    np.testing.assert_allclose(problem.bounds, m.bounds)
    assert problem.fitness(Q_TRUE) < 1e-10
    others = random_in(m.bounds, 200, 6)
    f = problem.fitness(others)
    assert f.shape == (200,) and (f > 1e-3).all()
    r = problem.residuals(others)
    norm = lambda v: np.sqrt((v * v).sum(axis=-1))  # noqa: E731
    np.testing.assert_allclose(f, norm(r[:, :3]) + norm(r[:, 3:]), rtol=1e-12)
    # Weights: w_p multiplies the distance, w_r the angle in radians.
    x = others[0]
    dP, dR = problem.position_error(x), np.radians(problem.rotation_error(x))
    assert problem.fitness(x) == pytest.approx(dP + 180 / np.pi * dR, rel=1e-12)
    half = fkopt.ik_problem(m, m.fk(Q_TRUE), objective=objective, w_p=0.5, w_r=2.0)
    assert half.fitness(x) == pytest.approx(0.5 * dP + 2.0 * dR, rel=1e-12)


@pytest.mark.parametrize("objective", ["paper", "geodesic"])
def test_ik_fitness_bit_identical_in_batches(objective):
    m = fkopt.mechanism("7dof-arm")
    problem = fkopt.ik_problem(m, m.fk(Q_TRUE), objective=objective)
    x = random_in(m.bounds, 30, 9).reshape(3, 10, 7)
    f = problem.fitness(x)
    assert f.shape == (3, 10)
    assert all(problem.fitness(x[i, j]) == f[i, j] for i in range(3) for j in range(10))
    assert np.array_equal(problem.residuals(x)[1], problem.residuals(x[1]))


@pytest.mark.parametrize("objective", ["paper", "geodesic"])
def test_ik_round_trip_least_squares(objective):
    m = fkopt.mechanism("7dof-arm")
    rng = np.random.default_rng(7)
    for q in random_in(m.bounds, 4, 8):
        problem = fkopt.ik_problem(m, m.fk(q), objective=objective)
        # a local solver from 10 deg away: the residuals lead to the target (no swarm needed;
        # unbounded, since bounded trust regions crawl along the joint limits of this arm)
        x = least_squares(problem.residuals, q + rng.uniform(-10, 10, 7), method="dogbox").x
        assert problem.position_error(x) < 1e-6
        assert problem.rotation_error(x, "geodesic") < 1e-6


def test_ik_abc_reduces_error():
    m = fkopt.mechanism("7dof-arm")
    problem = fkopt.ik_problem(m, m.fk(Q_TRUE))
    result = fkopt.solve(problem, "abc", population=50, iterations=200, runs=2, seed=3)
    assert (result.history[:, -1] < 0.25 * result.history[:, 0]).all()
    assert np.allclose(result.fitness, problem.fitness(result.x))


def test_euler_difference_wraps_at_180():
    m = fkopt.mechanism("7dof-arm")
    q = Q_TRUE.copy()
    q[0] += -179.95 - m.fk(q)[3]        # base rotation shifts alpha: make it -179.95 deg
    pose = m.fk(q)
    assert pose[3] == pytest.approx(-179.95)
    target = pose.copy()
    target[3] = 179.95                   # 0.1 deg away across the cut
    for objective in ("paper", "geodesic"):
        problem = fkopt.ik_problem(m, target, objective=objective)
        assert problem.rotation_error(q) == pytest.approx(0.1, abs=1e-6)
        assert problem.fitness(q) == pytest.approx(0.1, abs=1e-6)   # 0 mm + 0.1 deg


def test_target_euler_normalised():
    m = fkopt.mechanism("7dof-arm")
    a, b, g = m.fk(Q_TRUE)[3:]
    same = [*m.fk(Q_TRUE)[:3], a - 180.0, -b, g + 180.0]     # the same rotation, beta < 0
    problem = fkopt.ik_problem(m, same)
    np.testing.assert_allclose(problem.target[3:], [a, b, g], atol=1e-9)
    assert problem.fitness(Q_TRUE) < 1e-10
    named = fkopt.ik_problem(m, dict(zip(m.pose_names, m.fk(Q_TRUE))), objective="geodesic")
    assert named.fitness(Q_TRUE) < 1e-10


def test_ik_errors():
    m = fkopt.mechanism("7dof-arm")
    with pytest.raises(fkopt.FkoptError,
                       match=r"target \(1500, 1000, 0\) unreachable \(distance 1802\.8 mm > reach 1761\.8 mm\)"):
        fkopt.ik_problem(m, [1500, 1000, 0, 0, 0, 0])
    with pytest.raises(fkopt.FkoptError, match="objective 'euler' unknown; allowed: paper, geodesic"):
        fkopt.ik_problem(m, m.fk(Q_TRUE), objective="euler")
    with pytest.raises(fkopt.FkoptError, match="expected 6 values"):
        fkopt.ik_problem(m, [1, 2, 3])
    with pytest.raises(fkopt.FkoptError, match="missing gamma"):
        fkopt.ik_problem(m, dict(x=0, y=0, z=500, alpha=0, beta=0))
    with pytest.raises(fkopt.FkoptError, match="serial arm"):
        fkopt.ik_problem(fkopt.mechanism("3-ppr"), [0, 0, 0, 0, 0, 0])
    with pytest.raises(fkopt.FkoptError, match="parallel mechanism"):
        fkopt.fk_problem(m, Q_TRUE)
    with pytest.raises(fkopt.FkoptError, match="w_r"):
        fkopt.ik_problem(m, m.fk(Q_TRUE), w_r=-1)


# -- rotation helpers -------------------------------------------------------------------------
@settings(max_examples=50, deadline=None)
@given(st.floats(-179, 179), st.floats(0.5, 179.5), st.floats(-179, 179))
def test_zyz_round_trip(a, b, g):
    R = rotations.zyz(*np.radians([a, b, g]))
    np.testing.assert_allclose(rotations.to_array(R),
                               Rotation.from_euler("ZYZ", [a, b, g], degrees=True).as_matrix(), atol=1e-12)
    np.testing.assert_allclose(np.degrees(rotations.zyz_angles(R)), [a, b, g], atol=1e-8)


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_geodesic_angle_matches_scipy(seed):
    A, B = Rotation.random(2, random_state=seed)
    ref = (A.inv() * B).magnitude()
    got = rotations.geodesic_angle(soa(A.as_matrix()), soa(B.as_matrix()))
    assert got == pytest.approx(ref, abs=1e-12)
    assert rotations.geodesic_angle(soa(B.as_matrix()), soa(A.as_matrix())) == pytest.approx(ref, abs=1e-12)
    vec = rotations.rotation_vector(soa(A.as_matrix()), soa(B.as_matrix()))
    assert np.sqrt(sum(v * v for v in vec)) == pytest.approx(got, abs=1e-12)


def test_geodesic_angle_near_zero_and_pi():
    eye = soa(np.eye(3))
    for angle_ in (1e-9, np.pi - 1e-9, np.pi):
        M = Rotation.from_rotvec([0.0, angle_, 0.0]).as_matrix()
        assert rotations.geodesic_angle(eye, soa(M)) == pytest.approx(angle_, abs=1e-12)
    np.testing.assert_allclose(rotations.rotation_vector(eye, soa(Rotation.from_rotvec([1e-9, 0, 0]).as_matrix())),
                               [1e-9, 0, 0], atol=1e-20)
