"""6-SPS Stewart-Gough platform and the liu2008 CMM preset: SPEC.md values, overrides, round trips."""
import json

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.optimize import least_squares

import fkopt
from fkopt.kinematics.assembly_modes import all_solutions
from fkopt.mechanisms.sps6 import DIETMAIER_BASE, DIETMAIER_PLATFORM, FULL_TURN, SixSPS, SixSPSCMM

LEGS = np.array([0.750, 0.780, 0.800, 0.900, 0.870, 0.850])               # liu2008 Tab. 3
EXACT = np.array([0.03986047, 0.09593005, 0.92523456, -12.6973253, 6.4030949, 15.1332059])  # SPEC.md
PRINTED = np.array([0.039860, 0.095930, 0.925235, -12.697325, 6.403095, 15.133206])         # Tab. 3


@pytest.fixture(scope="module")
def cmm():
    return fkopt.mechanism("6-sps-cmm")


def test_registered():
    assert isinstance(fkopt.mechanism("6-sps"), SixSPS)
    m = fkopt.mechanism("6-sps-cmm")
    assert isinstance(m, SixSPSCMM) and m.paper == "liu2008"
    json.dumps(m.describe())                                        # JSON-able description


def test_liu2008_joint_points(cmm):
    # eq. (2): theta_b = 60 -+ 15, 180 -+ 15, 300 -+ 15; theta_p = 15, 105, 135, 225, 255, 345 (deg).
    base, platform, probe = cmm.points()
    tb = np.degrees(np.arctan2(base[:, 1], base[:, 0])) % 360
    tp = np.degrees(np.arctan2(platform[:, 1], platform[:, 0])) % 360
    np.testing.assert_allclose(tb, [45, 75, 165, 195, 285, 315], atol=1e-12)
    np.testing.assert_allclose(tp, [15, 105, 135, 225, 255, 345], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(base, axis=1), 0.5)
    np.testing.assert_allclose(np.linalg.norm(platform, axis=1), 0.225)
    np.testing.assert_allclose(probe, [0, 0, 0.18])


def test_exact_solution_reproduces_printed_legs(cmm):
    # SPEC.md: the exact solution (8 significant digits) gives the Tab. 3 legs.
    assert np.abs(cmm.ik(EXACT) - LEGS).max() < 5e-9


def test_printed_pose_is_054_micrometres_off(cmm):
    # SPEC.md: the printed pose reproduces the legs to 0.54 um.
    err = np.abs(cmm.ik(PRINTED) - LEGS).max()
    assert 0.5e-6 < err < 0.55e-6


def test_fk_of_printed_legs_is_the_exact_pose(cmm):
    sol = least_squares(lambda x: cmm.ik(x) - LEGS, PRINTED + [0.01, -0.01, 0.02, 2, -2, 2],
                        xtol=1e-15, ftol=1e-15, gtol=1e-15)
    np.testing.assert_allclose(sol.x, EXACT, atol=1e-6)
    sols = all_solutions(cmm, LEGS, seed=3)
    assert len(sols) == 1                                           # unique in the default workspace
    np.testing.assert_allclose(sols[0].x, EXACT, atol=1e-6)
    assert sols[0].residual < 1e-12


def test_fitness_objectives(cmm):
    # liu2008's fitness is sum |l_i - l'_i| (objective "absolute").
    p = fkopt.fk_problem(cmm, LEGS, objective="absolute")
    assert p.fitness(EXACT) < 1.2e-8
    np.testing.assert_allclose(p.fitness(PRINTED), np.abs(cmm.ik(PRINTED) - LEGS).sum())
    assert cmm.in_bounds(EXACT) and cmm.in_bounds(PRINTED)


def test_ik_matches_vector_reference_and_is_batch_invariant(cmm):
    rng = np.random.default_rng(1)
    lo, hi = cmm.bounds.T
    X = lo + (hi - lo) * rng.random((7, 33, 6))
    ref = np.linalg.norm(cmm.ik_vectors(X), axis=-1)
    np.testing.assert_allclose(cmm.ik(X), ref, rtol=1e-14)
    # elementwise: each pose gives bit-identical legs alone or in any batch
    full = cmm.ik(X)
    assert np.array_equal(full[3], cmm.ik(X[3]))
    assert np.array_equal(full[2, 5], cmm.ik(X[2, 5]))
    assert np.array_equal(full.reshape(-1, 6), cmm.ik(X.reshape(-1, 6)))


def test_general_platform_legs_by_definition():
    m = fkopt.mechanism("6-sps", probe=[0.01, -0.02, 0.3])
    x = np.array([0.3, -0.2, 1.1, 20.0, -35.0, 110.0])
    a, b, g = np.radians(x[3:])
    Rx = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    Ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
    Rz = np.array([[np.cos(g), -np.sin(g), 0], [np.sin(g), np.cos(g), 0], [0, 0, 1]])
    R = Rz @ Ry @ Rx
    s = np.array([0.01, -0.02, 0.3])
    legs = [np.linalg.norm(R @ p + x[:3] - R @ s - b_) for p, b_ in
            zip(np.array(DIETMAIER_PLATFORM), np.array(DIETMAIER_BASE))]
    np.testing.assert_allclose(m.ik(x), legs, rtol=1e-14)


def test_cmm_overrides():
    default = SixSPSCMM()
    x = EXACT
    # explicit points equal to the symmetric ones: same legs
    base, platform, _ = default.points()
    explicit = SixSPSCMM(base=base.tolist(), platform=platform.tolist())
    np.testing.assert_allclose(explicit.ik(x), default.ik(x), rtol=1e-15)
    # the symmetric parameters change the legs
    assert not np.allclose(SixSPSCMM(Rb=0.6).ik(x), default.ik(x))
    assert not np.allclose(SixSPSCMM(ls=0.0).ik(x), default.ik(x))
    with pytest.raises(fkopt.FkoptError, match="not both"):
        SixSPSCMM(base=base.tolist(), Rb=0.6)
    with pytest.raises(fkopt.FkoptError, match="geometry"):
        SixSPS(base=[[0, 0, 0]] * 5)
    with pytest.raises(fkopt.FkoptError, match="geometry"):
        SixSPSCMM(radius=1)


def test_bounds():
    cmm = SixSPSCMM()
    assert cmm.bounds.tolist() == [[-0.2, 0.2], [-0.2, 0.2], [0.7, 1.1], [-30, 30], [-30, 30], [-30, 30]]
    full = SixSPSCMM(bounds=FULL_TURN)
    assert full.bounds[3:].tolist() == [[-180, 180]] * 3 and full.bounds[2].tolist() == [0.7, 1.1]
    assert SixSPSCMM(bounds=SixSPSCMM.full_turn_bounds()).bounds[4].tolist() == [-180, 180]
    general = SixSPS()
    reach = 2 * (np.linalg.norm(DIETMAIER_BASE, axis=1).max() + np.linalg.norm(DIETMAIER_PLATFORM, axis=1).max())
    np.testing.assert_allclose(general.bounds[:3], [[-reach, reach]] * 3)
    assert general.bounds[3:].tolist() == [[-180, 180]] * 3
    # the default geometry's bounds equal the class-level defaults
    assert SixSPS.default_bounds == {n: tuple(b) for n, b in zip(general.pose_names, general.bounds.tolist())}
    with pytest.raises(fkopt.FkoptError, match="unknown variable"):
        SixSPSCMM(bounds={"theta": [0, 1]})


@settings(max_examples=12, deadline=None)
@given(st.lists(st.floats(0.02, 0.98), min_size=6, max_size=6))
def test_fk_ik_round_trip(u):
    # FK(IK(pose)) contains the pose: all assembly modes in the CMM workspace for its legs.
    cmm = SixSPSCMM()
    lo, hi = cmm.bounds.T
    pose = lo + (hi - lo) * np.array(u)
    sols = all_solutions(cmm, cmm.ik(pose), starts=600, seed=0)
    dist = [np.abs(s.x - pose).max() for s in sols]
    assert min(dist) < 1e-7
    assert all(s.residual < 1e-9 for s in sols)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(-1, 1), min_size=6, max_size=6))
def test_least_squares_round_trip_general(u):
    m = SixSPS()
    pose = np.array([0.3, 0.2, 1.0, 0, 0, 0]) + np.array(u) * [0.3, 0.3, 0.3, 40, 40, 40]
    legs = m.ik(pose)
    sol = least_squares(lambda x: m.ik(x) - legs, pose + np.array(u)[::-1] * [0.02, 0.02, 0.02, 2, 2, 2],
                        xtol=1e-15, ftol=1e-15, gtol=1e-15)
    np.testing.assert_allclose(m.ik(sol.x), legs, atol=1e-10)
