"""ACO (wu2015), PSO, P-ABC (chang2024), Newton-Raphson, Levenberg-Marquardt and the *+lm hybrids."""
import re

import numpy as np
import pytest
from scipy.optimize import least_squares

import fkopt
from fkopt.algorithms.aco import ACO
from fkopt.algorithms.pso import PSO, PSOState

SWARMS = ["aco", "pso", "pabc", "abc+lm", "gabc+lm", "pso+lm"]
ALL = SWARMS + ["nr", "lm"]


class SphereProblem:
    """f(x) = |x - x*|^2 on a box; residuals x - x* (square, for Newton/LM)."""

    def __init__(self, centre=(0.3, -1.2, 2.5), half=5.0):
        self.centre = np.asarray(centre, dtype=float)
        self.variable_names = tuple(f"x{i}" for i in range(len(self.centre)))
        self.variable_units = ("",) * len(self.centre)
        self.bounds = np.array([[-half, half]] * len(self.centre))

    @property
    def dim(self):
        return len(self.variable_names)

    def residuals(self, x):
        return np.asarray(x, dtype=float) - self.centre

    def fitness(self, x):
        r = self.residuals(x)
        return (r * r).sum(axis=-1)


class Saturated:
    """1-D residual r = min(x, 1)^2 - 1/4: root 0.5, flat (singular Jacobian) for x >= 1."""

    variable_names = ("x",)
    variable_units = ("",)
    bounds = np.array([[-3.0, 3.0]])
    dim = 1

    def residuals(self, x):
        x = np.asarray(x, dtype=float)
        return np.minimum(x, 1.0) ** 2 - 0.25

    def fitness(self, x):
        r = self.residuals(x)
        return (r * r).sum(axis=-1)


class Overdetermined(SphereProblem):
    def residuals(self, x):
        r = super().residuals(x)
        return np.concatenate([r, r[..., :1]], axis=-1)


@pytest.fixture(scope="module")
def rps():
    m = fkopt.mechanism("3-rps")
    return fkopt.fk_problem(m, m.ik([9, 13, 622]))


# -- convergence ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", ALL)
def test_sphere_below_1e10(name):
    sphere = SphereProblem()
    population, iterations = (30, 1000) if name == "aco" else (20, 300)
    res = fkopt.solve(sphere, name, population=population, iterations=iterations, runs=3, seed=5)
    assert np.all(res.fitness < 1e-10)
    np.testing.assert_allclose(res.x, np.broadcast_to(sphere.centre, res.x.shape), atol=1e-5)
    assert np.all(np.diff(res.history, axis=1) <= 0)          # best-so-far is monotone
    assert np.all(np.diff(res.evaluation_history, axis=1) >= 0)


@pytest.mark.parametrize("name", SWARMS)
def test_optimum_outside_box_ends_on_the_bound(name):
    sphere = SphereProblem(centre=(7.0, 0.0, -1.0))           # x0* = 7 lies beyond the bound 5
    res = fkopt.solve(sphere, name, population=20, iterations=300, runs=2, seed=1, snapshots=[300])
    assert np.all((res.snapshots[300] >= -5) & (res.snapshots[300] <= 5))
    np.testing.assert_allclose(res.x[:, 0], 5.0, atol=1e-4)


@pytest.mark.parametrize("name", ["pso", "pabc", "gabc+lm", "pso+lm"])
def test_rps_case_solved(rps, name):
    res = fkopt.solve(rps, name, population=10, iterations=300, runs=3, seed=1)
    assert np.all(res.fitness < 1e-16)
    np.testing.assert_allclose(res.x, np.broadcast_to([9, 13, 622], res.x.shape), atol=1e-6)


# -- reproducibility -----------------------------------------------------------------------
@pytest.mark.parametrize("name", SWARMS + ["nr", "lm"])
def test_batch_and_single_runs_identical(rps, name):
    # Same process, same numpy/LAPACK build: nr/lm solve each small system by its own LAPACK
    # call, so this holds on any machine; across builds or CPUs only tolerances hold (lm.py).
    kw = dict(population=8, iterations=60, runs=3, seed=11, x_history=True)
    a = fkopt.solve(rps, name, **kw)
    b = fkopt.solve(rps, name, batch=False, **kw)
    c = fkopt.solve(rps, name, **{**kw, "runs": 1}, run_ids=[2])
    again = fkopt.solve(rps, name, **kw)
    for other in (b, again):
        np.testing.assert_array_equal(a.history, other.history)
        np.testing.assert_array_equal(a.x_history, other.x_history)
        np.testing.assert_array_equal(a.evaluation_history, other.evaluation_history)
        assert a.extras.keys() == other.extras.keys()
        for key in a.extras:
            np.testing.assert_array_equal(a.extras[key], other.extras[key])
    np.testing.assert_array_equal(a.history[2:], c.history)


@pytest.mark.parametrize("name", ["aco", "pso", "pabc"])
def test_seeds_differ(rps, name):
    a = fkopt.solve(rps, name, population=8, iterations=20, runs=2, seed=1)
    b = fkopt.solve(rps, name, population=8, iterations=20, runs=2, seed=2)
    assert not np.array_equal(a.history, b.history)
    assert not np.array_equal(a.history[0], a.history[1])     # runs of one seed differ too


# -- ACO -----------------------------------------------------------------------------------
def test_aco_pheromone_and_snapshots(rps):
    res = fkopt.solve(rps, "aco", population=10, iterations=50, runs=2, seed=3, snapshots=[0, 50])
    best, mean = res.extras["pheromone_best"], res.extras["pheromone_mean"]
    assert best.shape == mean.shape == (2, 51)
    assert np.all(best <= 0) and np.all(mean <= best)
    np.testing.assert_allclose(best[:, 0], -res.history[:, 0])   # tau = -f at the start (eq. 16)
    assert res.snapshots[0].shape == res.snapshots[50].shape == (2, 10, 3)
    assert np.all(np.diff(res.evaluation_history, axis=1) == 10)


@pytest.mark.parametrize("params", [{"step_rule": "adaptive"}, {"local_scale": "width"}])
def test_aco_step_variants_solve_sphere(params):
    res = fkopt.solve(SphereProblem(), "aco", population=30, iterations=1000, runs=2, seed=2, params=params)
    assert np.all(res.fitness < 1e-10)


def test_aco_solves_wu2015_case():
    """wu2015 Sec. 5: (20 mm, 30 mm, 15 deg); both exact branches fit the inputs (ppr3.py)."""
    m = fkopt.mechanism("3-ppr")
    joints = m.ik([20, 30, 15])
    res = fkopt.solve(fkopt.fk_problem(m, joints), "aco", population=30, iterations=1000, runs=4,
                      seed=1, snapshots=[0, 500, 1000])
    branches = m.fk_exact(joints)                                  # (2, 3)
    err = np.abs(res.x[:, None, :] - branches[None]).max(axis=-1).min(axis=-1)
    assert np.median(res.fitness) < 1e-8 and np.median(err) < 1e-3   # wu2015 Tab. 1: ~1e-4
    spread = {t: np.ptp(res.snapshots[t], axis=1) for t in (0, 500, 1000)}   # (runs, 3)
    assert np.all(spread[0][:, :2] > 60)                           # Fig. 4: ants spread over the box
    assert np.all(spread[1000][:, 1] < spread[0][:, 1] / 3)        # Fig. 5-6: they gather (in y;
    # along theta they line the valley joining the two branches theta = +-15 deg)


def test_aco_transfer_probability_reading():
    tau = np.array([[-1.0, -1.5, -3.0, -1.0], [0.0, -2.0, 0.0, -1e-300]])
    P = ACO.transfer_probability(tau)
    np.testing.assert_allclose(P[0], [0.0, 0.5, 2.0, 0.0])      # (tau_b - tau_j) / |tau_b|
    assert P[1, 0] == P[1, 2] == 0 and np.isinf(P[1, 1]) and np.isinf(P[1, 3])


# -- PSO / P-ABC ---------------------------------------------------------------------------
def test_pso_linear_inertia_schedule():
    algo = PSO(inertia="linear", w_max=0.5, w_min=0.1)
    x = np.zeros((1, 2, 1))
    state = PSOState(x=x, f=np.zeros((1, 2)), pos=x, vel=x, t=1, span=500)
    assert algo.inertia_weight(state) == pytest.approx(0.5 - 0.4 / 500)
    state.t = 500
    assert algo.inertia_weight(state) == pytest.approx(0.1)
    assert PSO(w=0.8).inertia_weight(state) == 0.8


def test_pso_paper_settings_run(rps):
    liu = fkopt.solve(rps, "pso", population=20, iterations=100, runs=2, seed=1,
                      params=dict(inertia="linear", w_max=0.5, w_min=0.1, c1=1.8, c2=1.8, v_max=1.0))
    chang = fkopt.solve(rps, "pso", population=20, iterations=100, runs=2, seed=1,
                        params=dict(w=0.8, c1=2, c2=2))
    assert np.all(liu.fitness < chang.history[:, 0]) and np.all(chang.fitness < chang.history[:, 0])


def test_pabc_counts_evaluations_per_phase(rps):
    pop, iters = 10, 40
    res = fkopt.solve(rps, "pabc", population=pop, iterations=iters, runs=3, seed=2,
                      params=dict(switch=0.25))
    d = np.diff(res.evaluation_history, axis=1)
    assert np.all(d[:, :10] == pop)                          # PSO phase: one evaluation per particle
    assert np.all((d[:, 10:] == 2 * pop) | (d[:, 10:] == 2 * pop + 1))   # ABC: employed + onlookers (+scout)
    assert res.evaluation_history[0, 0] == pop


def test_pabc_switch_extremes_match_components(rps):
    kw = dict(population=8, iterations=30, runs=2, seed=4)
    pure_pso = fkopt.solve(rps, "pabc", params=dict(switch=1.0), **kw)
    np.testing.assert_array_equal(pure_pso.history, fkopt.solve(rps, "pso", **kw).history)


# -- Newton-Raphson --------------------------------------------------------------------------
def test_nr_quadratic_convergence_on_rps(rps):
    res = fkopt.solve(rps, "nr", x0=[9.4, 12.7, 624.0], iterations=8, runs=1)
    f = res.history[0]
    assert f[-1] < 1e-20
    steps = int(np.argmax(f < 1e-20))
    assert steps <= 4
    for a, b in zip(f[:steps], f[1:steps + 1]):
        if a < 1.0 and b > 1e-24:                             # above the rounding floor (~1e-26)
            assert b <= 10 * a * a                            # |r_{k+1}| <~ C |r_k|^2
    np.testing.assert_allclose(res.x[0], [9, 13, 622], atol=1e-9)
    assert res.evaluation_history[0, 0] == 2                 # r and the analytic J (1 + 1)
    assert res.evaluation_history[0, 1] == 4
    assert res.extras["singular"].max() == 0


def test_nr_start_point_forms(rps):
    single = fkopt.solve(rps, "nr", x0=[5, 5, 600], iterations=10, runs=2)
    np.testing.assert_array_equal(single.history[0], single.history[1])
    rows = fkopt.solve(rps, "nr", x0=[[5, 5, 600], [-5, 10, 650]], iterations=10, runs=2, x_history=True)
    np.testing.assert_array_equal(rows.history[0], single.history[0])
    np.testing.assert_array_equal(rows.x_history[1, 0], [-5, 10, 650])
    assert np.all(rows.fitness < 1e-20)


def test_bad_start_points(rps):
    with pytest.raises(fkopt.FkoptError, match=r"outside the bounds.*z \[400, 700\]"):
        fkopt.solve(rps, "nr", x0=[9, 13, 800])
    with pytest.raises(fkopt.FkoptError, match="outside the bounds"):
        fkopt.solve(rps, "lm", x0=[[9, 13, 600], [25, 0, 600]], runs=2)
    with pytest.raises(fkopt.FkoptError, match="run 1 has none"):
        fkopt.solve(rps, "nr", x0=[[9, 13, 600]], runs=2)
    with pytest.raises(fkopt.FkoptError, match="start point has 2 values"):
        fkopt.solve(rps, "lm", x0=[9, 13])


def test_nr_needs_square_system():
    with pytest.raises(fkopt.FkoptError, match="as many residuals as unknowns"):
        fkopt.solve(Overdetermined(), "nr", iterations=3)
    res = fkopt.solve(Overdetermined(), "lm", iterations=30, population=3)   # LM takes any count
    assert res.fitness[0] < 1e-20


def test_nr_singular_jacobian():
    with pytest.raises(fkopt.FkoptError, match="singular Jacobian at start point"):
        fkopt.solve(Saturated(), "nr", x0=[1.5], iterations=3)
    # From 0.1 the Newton step overshoots to 1.3, where the residual is flat: kept, recorded.
    res = fkopt.solve(Saturated(), "nr", x0=[0.1], iterations=4, snapshots=[4])
    assert res.extras["singular"][0].tolist() == [0, 1, 1, 1, 1]
    np.testing.assert_allclose(res.snapshots[4][0, 0], [1.3], rtol=1e-6)
    np.testing.assert_array_equal(res.x[0], [0.1])            # the best point seen is the start
    assert res.evaluation_history[0].tolist() == [3, 6, 6, 6, 6]   # a frozen point costs nothing


# -- Levenberg-Marquardt -------------------------------------------------------------------
def test_lm_agrees_with_scipy(rps):
    starts = np.array([[0.0, 0.0, 550.0], [-15.0, 15.0, 450.0], [18.0, -5.0, 690.0]])
    res = fkopt.solve(rps, "lm", x0=starts, iterations=60, runs=3)
    lo, hi = rps.bounds[:, 0], rps.bounds[:, 1]
    for k, x0 in enumerate(starts):
        ref = least_squares(rps.residuals, x0, bounds=(lo, hi), xtol=1e-15, ftol=1e-15, gtol=1e-15)
        np.testing.assert_allclose(res.x[k], ref.x, atol=1e-8)
        np.testing.assert_allclose(res.x[k], [9, 13, 622], atol=1e-8)
    assert np.all(res.fitness < 1e-20)


def test_lm_printed_inputs_spec_solution():
    """SPEC.md mao2017: the printed d has the exact solution (8.85873, 13.00352, 622.00677)."""
    m = fkopt.mechanism("3-rps")
    problem = fkopt.fk_problem(m, [598.8495, 671.5847, 629.4955])
    res = fkopt.solve(problem, "lm", population=5, iterations=60, runs=2, seed=1)
    np.testing.assert_allclose(res.x, [[8.85873, 13.00352, 622.00677]] * 2, atol=5e-5)
    assert np.all(res.fitness < 1e-20)


# -- hybrids -------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["abc+lm", "gabc+lm", "pso+lm"])
def test_hybrid_phases(rps, name):
    pop, iters = 10, 50
    res = fkopt.solve(rps, name, population=pop, iterations=iters, runs=3, seed=6,
                      params=dict(swarm_iterations=30))
    swarm = fkopt.solve(rps, name.split("+")[0], population=pop, iterations=30, runs=3, seed=6)
    np.testing.assert_array_equal(res.history[:, :31], swarm.history)   # the swarm phase is the swarm
    np.testing.assert_array_equal(res.evaluation_history[:, :31], swarm.evaluation_history)
    assert np.all(np.diff(res.history, axis=1) <= 0)
    d = np.diff(res.evaluation_history[:, 30:], axis=1)
    assert np.all(d[:, 0] >= 1 + 1 + 1)                      # LM start (r, analytic J) + first trial
    assert np.all(d[:, 1:] <= 1 + 2 * 3)                     # then at most one trial + J per run
    assert np.all(res.fitness < 1e-18)
    assert fkopt.algorithm(name).swarm_phase(600) == 120     # default: 20 % of the iterations


# -- parameters ----------------------------------------------------------------------------
@pytest.mark.parametrize("name,params,field", [
    ("pso", {"inertia": "quadratic"}, "inertia"),
    ("pso", {"v_max": -1}, "v_max"),
    ("aco", {"P0": -0.5}, "P0"),
    ("aco", {"rho": 1.5}, "rho"),
    ("aco", {"step": 0.1}, "step"),
    ("pabc", {"switch": 2}, "switch"),
    ("nr", {"tol": -1}, "tol"),
    ("lm", {"up": 0.5}, "up"),
    ("gabc+lm", {"rule": "other"}, "rule"),
    ("pso+lm", {"swarm_fraction": 1.5}, "swarm_fraction"),
])
def test_bad_parameters(name, params, field):
    with pytest.raises(fkopt.FkoptError, match=re.escape(f"algorithm '{name}' parameter '{field}'")):
        fkopt.algorithm(name, **params)


def test_local_flags():
    assert fkopt.algorithm("nr").local and fkopt.algorithm("lm").local
    assert not any(fkopt.algorithm(n).local for n in SWARMS)
