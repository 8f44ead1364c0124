"""The 6-6 platform's parameter homotopy (fkopt.kinematics.sps6_homotopy, its compiled tracker) and
all_solutions' choice between it and the restart search (issue 38)."""
import numpy as np
import pytest

import fkopt
from fkopt.errors import FkoptError
from fkopt.kinematics import sps6_homotopy as hm
from fkopt.kinematics.assembly_modes import all_solutions, pose_distance, solutions_to_dict
from fkopt.mechanisms.sps6 import DIETMAIER_LEGS
from fkopt.numerics import path as numerics_path
from fkopt.tools.bench.fksgp import _cayley

kernel = pytest.importorskip("fkopt.numerics.compiled_homotopy")
# the homotopy runs on the compiled path; FKOPT_NUMERICS=numpy runs the restart search (tests/test_assembly.py)
pytestmark = pytest.mark.skipif(numerics_path.requested() == "numpy", reason="FKOPT_NUMERICS=numpy: no homotopy")


def _general_platform(rng, scale=1.0):
    """As fkSGP's genSGP and the fksgp bench draw one: points in [-2, 2]^3, a Cayley rotation."""
    X = np.vstack([np.zeros((1, 3)), 4 * rng.random((5, 3)) - 2]) * scale
    x = np.vstack([np.zeros((1, 3)), 4 * rng.random((5, 3)) - 2]) * scale
    R, t = _cayley(rng.standard_normal(3)), rng.standard_normal(3) * scale
    legs = np.sqrt(((R @ x.T + t[:, None] - X.T) ** 2).sum(0))
    return fkopt.mechanism("6-sps", base=X.tolist(), platform=x.tolist()), legs


def test_the_compiled_system_its_jacobian_and_parameter_derivative_match_the_forms():
    rng = np.random.default_rng(3)
    p0, p1 = hm._random_parameters(rng), hm._random_parameters(rng)
    P0, DP = hm._segment(p0, p1)
    h = rng.standard_normal(8) + 1j * rng.standard_normal(8)
    z = rng.standard_normal(8) + 1j * rng.standard_normal(8)
    s = 0.3 + 0.2j
    H, J, Hs = np.empty(8, complex), np.empty((8, 8), complex), np.empty(8, complex)

    def system(z, s):
        kernel._system(z, s, P0, DP, h, H, J, Hs)
        return H.copy(), J.copy(), Hs.copy()
    H0, J0, Hs0 = system(z, s)
    # the legs as the matrices of forms() give them, at the interpolated parameters
    ps = tuple(np.asarray(a) + s * (np.asarray(b) - np.asarray(a)) for a, b in zip(p0, p1))
    A, K = hm.forms(*ps)
    e, g = z[:4], z[4:]
    legs = np.einsum("a,iab,b->i", e, A, e) + np.einsum("a,iab,b->i", e, K, g) + 4 * (g @ g)
    np.testing.assert_allclose(H0, np.r_[legs, e @ g, h @ z - 1], rtol=1e-12, atol=1e-12)
    # holomorphic: central differences along real steps give the complex derivative
    step = 1e-6
    Jfd = np.stack([(system(z + step * u, s)[0] - system(z - step * u, s)[0]) / (2 * step) for u in np.eye(8)], 1)
    np.testing.assert_allclose(J0, Jfd, rtol=1e-7, atol=1e-7)
    np.testing.assert_allclose(Hs0, (system(z, s + step)[0] - system(z, s - step)[0]) / (2 * step), rtol=1e-7, atol=1e-7)


def test_the_start_system_has_forty_distinct_roots():
    p0, Z0, h0 = hm.start_system(kernel)
    assert Z0.shape == (hm.GENERIC_ROOTS, 8)
    assert hm._residual(Z0, p0, h0).max() < 1e-10
    D = np.abs(Z0[:, None] - Z0[None]).max(-1) + np.eye(len(Z0))
    assert D.min() > 1e-4


def test_homotopy_and_restart_search_find_the_same_sets_on_general_platforms(monkeypatch):
    rng = np.random.default_rng(38)
    for k, scale in enumerate((1.0, 1.0, 0.3, 100.0)):
        m, legs = _general_platform(rng, scale)
        got = all_solutions(m, legs, seed=k)
        assert got.method == "homotopy" and got.certificate.startswith("complete: 40 homotopy paths")
        monkeypatch.setenv("FKOPT_NUMERICS", "numpy")      # the reference path: the restart search
        ref = all_solutions(m, legs, seed=k)
        monkeypatch.delenv("FKOPT_NUMERICS")
        assert ref.method == "restarts" and ref.certificate.startswith("stopping rule")
        assert len(got) == len(ref) >= 1
        D = pose_distance(m, got.poses()[:, None], ref.poses()[None])
        assert (D.min(1) < 1e-7).all() and (D.min(0) < 1e-7).all()
        assert all(s.residual <= 1e-9 * max(1.0, legs.max()) for s in got)


def test_dietmaier_forty_real_roots_are_certified():
    m = fkopt.mechanism("6-sps")
    for seed in (0, 1, 2):
        sols = all_solutions(m, DIETMAIER_LEGS, seed=seed, method="homotopy")
        assert sols.method == "homotopy" and len(sols) == 40 and sols.starts == 40
        assert sum(s.hits for s in sols) == 40
        d = solutions_to_dict(sols)
        assert d["method"] == "homotopy" and d["certificate"].startswith("complete")


def test_a_special_geometry_falls_back_to_the_restart_search_and_says_why():
    m = fkopt.mechanism("6-sps-cmm")       # similar base and platform hexagons: fewer than 40 roots
    legs = m.ik(m.bounds.mean(1))
    got = all_solutions(m, legs, seed=0)
    assert got.method == "restarts" and "paths" in got.settings["homotopy"]
    ref = all_solutions(m, legs, seed=0, method="restarts")
    assert [s.pose for s in got] == [s.pose for s in ref]


def test_method_is_checked(monkeypatch):
    m = fkopt.mechanism("6-sps")
    with pytest.raises(FkoptError, match="allowed values auto, homotopy, restarts"):
        all_solutions(m, DIETMAIER_LEGS, method="elimination")
    with pytest.raises(FkoptError, match="is for a 6-SPS platform"):
        all_solutions(fkopt.mechanism("3-rps"), [600, 620, 640], method="homotopy")
    monkeypatch.setenv("FKOPT_NUMERICS", "numpy")
    with pytest.raises(FkoptError, match="runs on the compiled path"):
        all_solutions(m, DIETMAIER_LEGS, method="homotopy")
    # explicit starts run the restart search
    assert all_solutions(m, DIETMAIER_LEGS, starts=50).method == "restarts"


def test_without_a_start_system_the_restart_search_runs(monkeypatch):
    def broken(_kernel):
        raise RuntimeError("the 6-SPS start system has 39 roots after monodromy, not 40")
    monkeypatch.setattr(hm, "start_system", broken)
    m = fkopt.mechanism("6-sps")
    got = all_solutions(m, DIETMAIER_LEGS, seed=0)
    assert got.method == "restarts" and "39 roots" in got.settings["homotopy"] and len(got) == 40


def test_an_experiment_files_every_solution_entry_reports_the_certificate():
    from fkopt.solve import make_algorithm
    solver = make_algorithm("forward", {"solutions": "all"})
    m = fkopt.mechanism("6-sps")
    solver.prepare_solution_set(m)
    found = solver.solution_set(m, np.asarray(DIETMAIER_LEGS, dtype=float), 5)
    assert found.values.shape == (40, 6) and found.search["starts"] == 40
    assert found.search["stopping_rule"].startswith("complete: 40 homotopy paths")
