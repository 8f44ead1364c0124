"""The compiled numerics path (numba) held to the numpy/Python reference: the same chain FK and
frame Jacobian to 1e-12, and the same one-pose ``fkopt.inverse`` answers (joints, restarts,
evaluations) bit for bit, on real arms from example-robot-data and the DH arm of wang7dof."""
import numpy as np
import pytest

import fkopt
from fkopt.numerics import InverseOptions, chain as reference
from fkopt.numerics import path as numerics_path
from fkopt.mechanisms.urdf import example_robot, example_robots_folder

compiled = pytest.importorskip("fkopt.numerics.compiled", reason="numba is not installed")
TIPS = {"panda": "panda_hand_tcp", "ur5": "ee_link", "kinova": "j2s6s200_end_effector"}


def arms():
    out = [("7dof-arm", fkopt.mechanism("7dof-arm"))]
    if example_robots_folder() is not None:
        out += [(n, example_robot(n, tip=t)) for n, t in sorted(TIPS.items())]
    return out


def random_joints(m, n, seed):
    rng = np.random.default_rng(seed)
    return m.bounds[:, 0] + rng.random((n, m.dof)) * (m.bounds[:, 1] - m.bounds[:, 0])


@pytest.mark.parametrize("name,arm", arms(), ids=lambda v: v if isinstance(v, str) else "")
def test_compiled_chain_fk_and_jacobian_equal_the_reference(name, arm):
    ch = arm.chain()
    # both paths read the same chain in internal units (rad, m); any values exercise them equally
    for t in np.random.default_rng(1).uniform(-3.0, 3.0, (25, ch.dof)):
        p0, R0, J0 = reference.frame_jacobian1(ch, t.tolist())
        p1, R1, J1 = compiled.frame_jacobian(ch, t)
        assert np.max(np.abs(np.asarray(p0) - p1)) <= 1e-12
        assert np.max(np.abs(np.asarray(R0) - R1)) <= 1e-12
        assert np.max(np.abs(np.asarray(J0) - J1)) <= 1e-12


@pytest.mark.parametrize("name,arm", arms(), ids=lambda v: v if isinstance(v, str) else "")
def test_compiled_one_pose_inverse_gives_the_reference_answers(name, arm):
    targets = arm.fk(random_joints(arm, 8, 2))
    for k in range(8):
        pose = {key: v[k] for key, v in targets.items()} if isinstance(targets, dict) else targets[k]
        a = fkopt.inverse(arm, pose, seed=k, options=InverseOptions(compiled=False))
        b = fkopt.inverse(arm, pose, seed=k, options=InverseOptions(compiled=True))
        assert bool(a.solved) and bool(b.solved)
        assert np.array_equal(a.joints, b.joints)
        assert np.array_equal(a.restarts, b.restarts)
        for key in a.evaluations:
            assert np.array_equal(a.evaluations[key], b.evaluations[key])


@pytest.mark.parametrize("name,arm", arms(), ids=lambda v: v if isinstance(v, str) else "")
def test_a_target_frame_gives_the_reference_answers_on_both_paths_and_in_batches(name, arm):
    """fkopt.inverse given 4x4 tip frames (the rotation as given, no Euler angles): the compiled
    one-pose call, the Python reference and every row of a batch agree bit for bit, and every
    answer's FK is the frame to the tolerance."""
    q = random_joints(arm, 6, 5)
    frames = arm.fk_matrix(q)
    b = fkopt.inverse(arm, frames, seed=4, tol=(1e-9, 1e-9), options=InverseOptions(compiled=True))
    for k in range(6):
        one = [fkopt.inverse(arm, frames[k], seed=4, tol=(1e-9, 1e-9), options=InverseOptions(compiled=c))
               for c in (False, True)]
        assert np.array_equal(one[0].joints, one[1].joints) and np.array_equal(one[1].joints, b.joints[k])
        assert int(one[0].restarts) == int(one[1].restarts) == int(b.restarts[k])
        assert bool(one[1].solved)
        F = arm.fk_matrix(one[1].joints)                  # our own check, in the arm's length unit
        assert np.linalg.norm(F[:3, 3] - frames[k][:3, 3]) <= 1.01e-9
    slow = fkopt.inverse(arm, frames, seed=4, tol=(1e-9, 1e-9), options=InverseOptions(compiled=False))
    assert slow.solved.all() and b.solved.all()


def test_the_environment_switch_forces_the_reference(monkeypatch):
    monkeypatch.setenv(numerics_path.ENV, "numpy")
    assert numerics_path.compiled(None) is None
    monkeypatch.setenv(numerics_path.ENV, "bogus")
    with pytest.raises(fkopt.errors.FkoptError, match="allowed values auto, numpy, compiled"):
        numerics_path.requested()


@pytest.mark.parametrize("name,arm", arms(), ids=lambda v: v if isinstance(v, str) else "")
def test_compiled_batch_rows_are_the_one_pose_reference_answers(name, arm):
    """A batch through the compiled path solves every row as its one-pose call: the same joints,
    restarts and evaluations as the Python reference for that pose alone, whatever the batch."""
    targets = arm.fk(random_joints(arm, 6, 3))
    b = fkopt.inverse(arm, targets, seed=4, options=InverseOptions(compiled=True))
    assert b.joints.shape == (6, arm.dof) and b.solved.all()
    for k in range(6):
        a = fkopt.inverse(arm, targets[k], seed=4, options=InverseOptions(compiled=False))
        assert np.array_equal(a.joints, b.joints[k])
        assert int(a.restarts) == int(b.restarts[k])
        assert int(a.evaluations["jacobian"]) == int(b.evaluations["jacobian"][k])
        assert float(a.position_error) == pytest.approx(float(b.position_error[k]), abs=1e-12)
        assert float(a.rotation_error) == pytest.approx(float(b.rotation_error[k]), abs=1e-12)


def test_env_json_records_the_numerics_path_and_numbas_version(monkeypatch):
    from importlib.metadata import version
    from fkopt.provenance import environment
    monkeypatch.delenv(numerics_path.ENV, raising=False)
    got = environment()["numerics"]
    assert got == {"path": "compiled", "mode": "auto", "compiled_fitness": False, "numba": version("numba"), "env": ""}
    monkeypatch.setenv(numerics_path.ENV, "numpy")
    assert environment()["numerics"]["path"] == "numpy"
    monkeypatch.setenv(numerics_path.ENV, "compiled")
    assert environment()["numerics"]["compiled_fitness"] is True
    assert numerics_path.recorded({"numerics": {"mode": "numpy"}}) == "numpy"
    assert numerics_path.recorded({"fingerprint": {}}) == "auto"          # stored before the record
    assert numerics_path.recorded({"numerics": {"mode": "fast"}}) == "auto"


@pytest.mark.parametrize("stored", ["numpy", "compiled", None])
def test_check_reruns_with_the_path_env_json_recorded(tmp_path, monkeypatch, stored):
    """fkopt check sets FKOPT_NUMERICS from the stored env.json for the rerun, then restores it."""
    import json
    import shutil
    from pathlib import Path
    from fkopt.reproduce import check
    from fkopt.reproduce.store import Store
    src = Path(__file__).parents[1] / "results" / "mao2017" / "tab3_floor"     # a small stored result
    root = tmp_path / "results"
    shutil.copytree(src, root / src.parent.name / src.name)
    env_file = root / src.parent.name / src.name / "env.json"
    env = json.loads(env_file.read_text()) if env_file.exists() else {}
    env.pop("numerics", None)
    if stored is not None:
        env["numerics"] = {"path": stored, "mode": stored, "numba": "x", "env": ""}
    env_file.write_text(json.dumps(env))
    seen = []

    def rerun(config, folder, source=None):             # the stored files, as a rerun that matches
        seen.append(numerics_path.requested())
        for f in (root / src.parent.name / src.name).iterdir():
            if f.is_file():
                shutil.copy(f, folder / f.name)
    monkeypatch.setattr(check, "rerun_files", rerun)
    monkeypatch.setenv(numerics_path.ENV, "numpy" if stored == "compiled" else "compiled")
    check.check_experiment(Store(root).get(src.parent.name, src.name))
    assert seen == [stored or "auto"]                  # no record: auto, whatever is set here
    assert numerics_path.requested() == ("numpy" if stored == "compiled" else "compiled")


def test_compiled_3rps_fitness_within_its_documented_tolerance(monkeypatch):
    """FKOPT_NUMERICS=compiled: the 3-RPS fitness in one compiled pass. Its tan is the C
    library's, numpy's may be SIMD code an ulp away, so the tolerance is on the residual norm:
    |sqrt(f_compiled) - sqrt(f_numpy)| <= 1e-11 mm (legs of ~600 mm: ~100 ulps), at random
    poses and at poses 1e-6 away from the solution; the default path does not change."""
    m = fkopt.mechanism("3-rps")
    rng = np.random.default_rng(5)
    targets = m.bounds[:, 0] + rng.random((50, 3)) * (m.bounds[:, 1] - m.bounds[:, 0])
    p = fkopt.fk_problem(m, m.ik(targets))
    x = np.concatenate([m.bounds[:, 0] + rng.random((50, 200, 3)) * (m.bounds[:, 1] - m.bounds[:, 0]),
                        targets[:, None, :] + rng.normal(0.0, 1e-6, (50, 200, 3))], axis=1)
    monkeypatch.setenv(numerics_path.ENV, "auto")
    f_numpy = p.fitness(x)
    assert m.compiled_fitness(x.reshape(-1, 3), m.ik(targets).T, False) is None
    monkeypatch.setenv(numerics_path.ENV, "compiled")
    f_compiled = p.fitness(x)
    assert f_compiled.shape == f_numpy.shape == (50, 400)
    assert np.abs(np.sqrt(f_compiled) - np.sqrt(f_numpy)).max() <= 1e-11
    p_abs = fkopt.fk_problem(m, m.ik(targets), objective="absolute")
    a_compiled = p_abs.fitness(x)
    monkeypatch.setenv(numerics_path.ENV, "auto")
    assert np.abs(a_compiled - p_abs.fitness(x)).max() <= 1e-11


@pytest.mark.parametrize("algorithm", ["gabc", "abc", "pso"])
def test_swarms_on_the_compiled_3rps_fitness_reach_what_the_numpy_path_reaches(monkeypatch, algorithm):
    """A swarm turns an ulp into another run, so the swarm tolerance is on outcomes: mao2017's
    case, 30 runs x 600 iterations, every run below 1e-12 on both paths (as the numpy path's
    stored results), with the same evaluation budget."""
    m = fkopt.mechanism("3-rps")
    p = fkopt.fk_problem(m, m.ik(np.array([9.0, 13.0, 622.0])))
    got = {}
    for mode in ("numpy", "compiled"):
        monkeypatch.setenv(numerics_path.ENV, mode)
        got[mode] = fkopt.solve(p, algorithm, population=10, iterations=600, runs=30, seed=1)
    for r in got.values():
        assert (r.fitness < 1e-12).all()
    assert abs(got["numpy"].evaluations.mean() - got["compiled"].evaluations.mean()) <= 30


def test_compiled_pso_step_is_the_numpy_step_up_to_the_fitness_tolerance(monkeypatch):
    """FKOPT_NUMERICS=compiled runs a PSO iteration on a 3-RPS FK problem in one compiled pass:
    from the same state and the same uniforms, positions and velocities equal numpy's bit for bit
    (the same operations in the same order), the fitness within the fitness tolerance
    (|sqrt(f_c) - sqrt(f_n)| <= 1e-11 mm), personal bests equal where the comparison agrees."""
    import copy
    from fkopt.algorithms.pso import PSO
    from fkopt.streams import RunStreams
    m = fkopt.mechanism("3-rps")
    targets = m.bounds[:, 0] + np.random.default_rng(6).random((4, 3)) * (m.bounds[:, 1] - m.bounds[:, 0])
    p = fkopt.fk_problem(m, m.ik(targets))
    alg = PSO()
    state = alg.initialize(p, 10, RunStreams(7, range(4)), None, 50)
    state.best_x, state.best_f = state.x[:, 0].copy(), state.f[:, 0].copy()
    for _ in range(3):                                     # a few numpy iterations: non-zero velocities
        alg.iterate(state, p, RunStreams(8, range(4)))
    got = {}
    for mode in ("numpy", "compiled"):
        monkeypatch.setenv(numerics_path.ENV, mode)
        s = copy.deepcopy(state)
        alg.iterate(s, p, RunStreams(9, range(4)))
        got[mode] = s
    a, b = got["numpy"], got["compiled"]
    assert PSO._compiled_step(p) is not None
    assert np.array_equal(a.pos, b.pos) and np.array_equal(a.vel, b.vel)
    assert np.abs(np.sqrt(a.f) - np.sqrt(b.f)).max() <= 1e-11
    assert np.array_equal(a.evaluations, b.evaluations)
    same = (a.f < state.f) == (b.f < state.f)
    assert np.array_equal(a.x[same], b.x[same])
    monkeypatch.setenv(numerics_path.ENV, "auto")
    assert PSO._compiled_step(p) is None                  # the default keeps numpy's bits


ABC_CASES = [("abc", {}, 10, {}), ("abc", {"limit": 3}, 10, {}), ("gabc", {}, 10, {}),
             ("gabc", {"rule": "zhu2010", "limit": 4}, 10, {}),
             ("gabc", {}, 40, {}),        # 40 > 32 bees: the roulette's binary search (abc.DENSE_ROULETTE)
             ("abc", {}, 10, {"objective": "absolute"}),
             ("gabc", {}, 10, {"target": 1e-6, "stop_at_target": True})]   # frozen runs: the log's active mask


@pytest.mark.parametrize("algorithm,params,population,options", ABC_CASES,
                         ids=lambda v: v if isinstance(v, str) else str(v))
@pytest.mark.parametrize("cases", [1, 3])
def test_compiled_abc_iteration_is_the_numpy_iteration_on_the_compiled_fitness(monkeypatch, algorithm, params,
                                                                                 population, options, cases):
    """FKOPT_NUMERICS=compiled runs an ABC/GABC iteration on a 3-RPS FK problem in one compiled
    pass (fkopt.numerics.compiled.abc_rps3): the same draws, the same operations and the same
    fitness function as the numpy phases on the compiled fitness, so every record is equal bit
    for bit -- histories, points, evaluation counts and the evaluation log -- scouts included
    (small limits make them fly); against the numpy fitness the tolerance is the outcome one
    (test above)."""
    from fkopt.algorithms.abc import ABC
    m = fkopt.mechanism("3-rps")
    targets = m.bounds[:, 0] + np.random.default_rng(11).random((cases, 3)) * (m.bounds[:, 1] - m.bounds[:, 0])
    joints = m.ik(targets)
    options = dict(options)
    p = fkopt.fk_problem(m, joints[0] if cases == 1 else joints, objective=options.pop("objective", "squared"))
    monkeypatch.setenv(numerics_path.ENV, "compiled")
    seen = []
    run_compiled = ABC._iterate_compiled
    monkeypatch.setattr(ABC, "_iterate_compiled", lambda self, *a: seen.append(1) or run_compiled(self, *a))
    fused = fkopt.solve(p, algorithm, population=population, iterations=120, runs=6, seed=3, params=params,
                        **options)
    monkeypatch.setattr(ABC, "_compiled_iteration", lambda self, problem: None)
    steps = fkopt.solve(p, algorithm, population=population, iterations=120, runs=6, seed=3, params=params,
                        **options)
    for name in ("x", "fitness", "history", "evaluation_history"):
        assert np.array_equal(getattr(fused, name), getattr(steps, name)), name
    for a, b in zip(fused.events, steps.events):
        assert np.array_equal(a, b)
    assert seen and (len(seen) == 120 or "target" in options)    # the compiled pass ran every iteration
    if "target" in options:                                # some runs froze at the target on the way
        assert (fused.iterations_done < 120).any()


def test_compiled_abc_iteration_only_where_it_is_the_same_algorithm(monkeypatch):
    """The compiled ABC iteration runs for fkopt's own ABC and GABC with raw selection under
    FKOPT_NUMERICS=compiled; a subclass, ``selection: karaboga`` or the default mode stay numpy."""
    from fkopt.algorithms.abc import ABC
    from fkopt.algorithms.gabc import GABC
    m = fkopt.mechanism("3-rps")
    p = fkopt.fk_problem(m, m.ik(np.array([9.0, 13.0, 622.0])))

    class Mine(ABC):
        name = "mine"
    monkeypatch.setenv(numerics_path.ENV, "compiled")
    assert ABC()._compiled_iteration(p)[2] == 0
    assert GABC()._compiled_iteration(p)[2] == 1 and GABC(rule="zhu2010")._compiled_iteration(p)[2] == 2
    assert ABC(selection="karaboga")._compiled_iteration(p) is None
    assert Mine()._compiled_iteration(p) is None
    monkeypatch.setenv(numerics_path.ENV, "auto")
    assert ABC()._compiled_iteration(p) is None


@pytest.mark.parametrize("cases", [1, 3])
def test_compiled_pso_iteration_is_the_numpy_iteration_on_the_compiled_fitness(monkeypatch, cases):
    """The compiled PSO iteration (with its evaluation-log bookkeeping) against the numpy
    iteration on the compiled fitness: every record equal bit for bit, the log included."""
    from fkopt.algorithms.pso import PSO
    m = fkopt.mechanism("3-rps")
    targets = m.bounds[:, 0] + np.random.default_rng(12).random((cases, 3)) * (m.bounds[:, 1] - m.bounds[:, 0])
    joints = m.ik(targets)
    p = fkopt.fk_problem(m, joints[0] if cases == 1 else joints)
    monkeypatch.setenv(numerics_path.ENV, "compiled")
    assert PSO._compiled_step(p) is not None
    fused = fkopt.solve(p, "pso", population=10, iterations=150, runs=6, seed=4)
    monkeypatch.setattr(PSO, "_compiled_step", staticmethod(lambda problem: None))
    steps = fkopt.solve(p, "pso", population=10, iterations=150, runs=6, seed=4)
    for name in ("x", "fitness", "history", "evaluation_history"):
        assert np.array_equal(getattr(fused, name), getattr(steps, name)), name
    for a, b in zip(fused.events, steps.events):
        assert np.array_equal(a, b)
