"""The compiled numerics path (numba) held to the numpy/Python reference: the same chain FK and
frame Jacobian to 1e-12, and the same one-pose ``fkopt.inverse`` answers (joints, restarts,
evaluations) bit for bit, on real arms from example-robot-data and the DH arm of wang7dof."""
from pathlib import Path

import numpy as np
import pytest

import fkopt
from fkopt.numerics import InverseOptions, chain as reference
from fkopt.numerics import path as numerics_path
from fkopt.mechanisms.urdf import example_robot, example_robots_folder

compiled = pytest.importorskip("fkopt.numerics.compiled", reason="numba is not installed")
rps3_kernels = pytest.importorskip("fkopt.mechanisms.rps3_kernels", reason="numba is not installed")
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
    from fkopt.run.provenance import environment
    monkeypatch.delenv(numerics_path.ENV, raising=False)
    got = environment()["numerics"]
    assert got == {"path": "compiled", "mode": "auto", "compiled_fitness": False, "numba": version("numba"),
                   "llvmlite": version("llvmlite"), "env": ""}
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


def test_compiled_3rps_fitness_is_the_numpy_fitness_bit_for_bit(monkeypatch):
    """FKOPT_NUMERICS=compiled: the 3-RPS fitness compiled around numpy's own np.tan (called in the
    numpy path's layout) gives the numpy path's bits, at random poses and 1e-6 from the solution,
    squared and absolute, also when the poses span several of the numpy fitness' blocks."""
    from fkopt.mechanisms import rps3
    m = fkopt.mechanism("3-rps")
    rng = np.random.default_rng(5)
    targets = m.bounds[:, 0] + rng.random((50, 3)) * (m.bounds[:, 1] - m.bounds[:, 0])
    x = np.concatenate([m.bounds[:, 0] + rng.random((50, 200, 3)) * (m.bounds[:, 1] - m.bounds[:, 0]),
                        targets[:, None, :] + rng.normal(0.0, 1e-6, (50, 200, 3))], axis=1)
    for objective in ("squared", "absolute"):
        p = fkopt.fk_problem(m, m.ik(targets), objective=objective)
        for block in (rps3.BLOCK, 7):
            monkeypatch.setattr(rps3, "BLOCK", block)
            monkeypatch.setenv(numerics_path.ENV, "auto")
            assert m.compiled_fitness(x.reshape(-1, 3), m.ik(targets).T, False) is None   # one call: numpy
            f_numpy = p.fitness(x)
            monkeypatch.setenv(numerics_path.ENV, "compiled")
            f_compiled = p.fitness(x)
            assert f_compiled.shape == f_numpy.shape == (50, 400)
            assert np.array_equal(f_compiled, f_numpy), (objective, block)


def test_numpy_tan_layout_is_the_numpy_fitness_call_and_the_libm_tan_differs():
    """The compiled swarms take numpy's tangents in the layout ThreeRPS.ik_columns gives np.tan
    (per block: the block's alphas, then its betas, contiguous). Held here: the layout of
    rps3_kernels.slot / numpy_tan against that construction, several blocks and a short last one;
    and why it matters -- the C library's tan (math.tan) differs from numpy's on some inputs on
    SIMD builds (reported, not required: on builds without SIMD tan both are libm's)."""
    import math
    rng = np.random.default_rng(3)
    n, block = 23, 5
    P = np.stack([rng.uniform(-20, 20, n), rng.uniform(-20, 20, n), rng.uniform(400, 700, n)], axis=1)
    arg = np.full(2 * n, np.nan)
    rps3_kernels._arguments(P, arg, block)
    want = np.concatenate([np.concatenate([P[s:s + block, 0], P[s:s + block, 1]]) for s in range(0, n, block)])
    assert np.array_equal(arg, want * (math.pi / 360.0))
    tan = np.empty(2 * n)
    rps3_kernels.numpy_tan(arg, tan, ((0, n),), block)
    assert np.array_equal(tan, np.concatenate([np.tan(arg[2 * s:2 * min(s + block, n)]) for s in range(0, n, block)]))
    big = rng.uniform(-20, 20, 20000) * (math.pi / 360.0)
    differ = float(np.mean(np.tan(big) != np.array([math.tan(v) for v in big])))
    assert 0.0 <= differ < 0.05          # ~0.7 % with AVX-512 SVML, 0 with libm


def test_numpys_tan_loop_called_from_compiled_code_is_np_tan_bit_for_bit():
    """numpy's own float64 tan loop, read from the ufunc object and called from compiled code
    (fkopt.numerics.ufunc_loop), gives np.tan's bits on every length (SIMD bodies and tails) and
    offset, values from tiny to huge and the specials; rps3_kernels.numpy_tan_loop cuts a fitness
    call's blocks as numpy_tan does and writes nothing outside its range."""
    from fkopt.numerics import ufunc_loop
    loop = rps3_kernels.numpy_tan_address()
    assert loop is not None                      # CPython with numpy's ufunc layout: read and verified
    rng = np.random.default_rng(8)
    for n in range(0, 140):
        a = rng.uniform(-1, 1, n + 6) * 10.0 ** rng.uniform(-6, 6, n + 6)
        a[rng.integers(0, n + 6, 2)] = (np.nan, -np.inf)
        start = int(rng.integers(0, 6))
        want, got = np.full(n + 6, 5.0), np.full(n + 6, 5.0)
        with np.errstate(all="ignore"):
            np.tan(a[start:start + n], out=want[start:start + n])
        ufunc_loop.call_unary_loop(loop[0], loop[1], a, got, start, n)
        assert np.array_equal(want.view(np.int64), got.view(np.int64)), n
    arg = rng.uniform(-0.2, 0.2, 2 * 40)
    for s0, sl, block in ((0, 40, 7), (3, 20, 7), (5, 0, 7), (0, 40, 64)):
        want, got = np.full(80, 5.0), np.full(80, 5.0)
        rps3_kernels.numpy_tan(arg, want, ((s0, sl),), block)
        rps3_kernels.numpy_tan_loop(loop[0], loop[1], arg, got, s0, sl, block)
        assert np.array_equal(want, got), (s0, sl, block)
    with pytest.raises(IndexError):
        ufunc_loop.call_unary_loop(loop[0], loop[1], arg, got, 70, 20)


def test_a_ufunc_loop_that_is_not_the_ufuncs_own_is_refused(monkeypatch):
    """unary_loop checks the loop it read against the ufunc itself: np.sin's loop offered as
    np.tan's is refused (None: the iterations call np.tan from Python), as are a two-argument
    ufunc and anything that is not a numpy ufunc."""
    from fkopt.numerics import ufunc_loop
    sin = ufunc_loop._read_loop(np.sin)
    assert sin is not None and sin != ufunc_loop._read_loop(np.tan)
    monkeypatch.setattr(ufunc_loop, "_read_loop", lambda ufunc: sin)
    ufunc_loop.unary_loop.cache_clear()
    try:
        assert ufunc_loop.unary_loop(np.tan) is None
        assert ufunc_loop.unary_loop(np.sin) == sin
    finally:
        monkeypatch.undo()
        ufunc_loop.unary_loop.cache_clear()
    assert ufunc_loop.unary_loop(np.add) is None and ufunc_loop.unary_loop(abs) is None
    assert ufunc_loop.unary_loop(np.tan) is not None


SWARM_CASES = [("pso", {}, 10, {}), ("abc", {}, 10, {}), ("abc", {"limit": 3}, 10, {}), ("gabc", {}, 10, {}),
               ("gabc", {"rule": "zhu2010", "limit": 4}, 10, {}),
               ("gabc", {}, 40, {}),        # 40 > 32 bees: the roulette's binary search (abc.DENSE_ROULETTE)
               ("abc", {}, 10, {"objective": "absolute"}),
               ("pso", {}, 10, {"objective": "absolute"}),
               ("gabc", {}, 10, {"target": 1e-6, "stop_at_target": True}),   # frozen runs: the log's active mask
               ("pabc", {}, 10, {}),        # PSO then ABC on one state (PSOState and ABCState fields)
               ("pso+lm", {}, 10, {}), ("gabc+lm", {}, 10, {})]   # a hybrid's swarm phase on its inner state


@pytest.mark.parametrize("algorithm,params,population,options", SWARM_CASES,
                         ids=lambda v: v if isinstance(v, str) else str(v))
@pytest.mark.parametrize("cases", [1, 3])
def test_compiled_swarms_give_the_numpy_paths_runs_bit_for_bit(monkeypatch, algorithm, params, population, options,
                                                               cases):
    """The default path (FKOPT_NUMERICS unset: auto) runs PSO, ABC and GABC on 3-RPS compiled
    (fkopt.algorithms.pso_kernels / abc_kernels on fkopt.mechanisms.rps3_kernels, around numpy's np.tan); through the real solver,
    every record equals FKOPT_NUMERICS=numpy's bit for bit -- points, fitness, histories,
    evaluation counts and the evaluation log -- on two seeds, one and three cases (a target
    per row: the scouts' own fitness call), scouts included (small limits make them fly). fkopt's
    own ABC and GABC run many iterations per compiled call there (numpy's tan loop called from
    compiled code, ABC.compiled_advance) unless a run may stop at its target."""
    from fkopt.algorithms.abc import ABC
    from fkopt.algorithms.pso import PSO
    m = fkopt.mechanism("3-rps")
    targets = m.bounds[:, 0] + np.random.default_rng(11).random((cases, 3)) * (m.bounds[:, 1] - m.bounds[:, 0])
    joints = m.ik(targets)
    options = dict(options)
    p = fkopt.fk_problem(m, joints[0] if cases == 1 else joints, objective=options.pop("objective", "squared"))
    ran = []
    spy, spy_advance = rps3_kernels.numpy_tan, ABC._advance_compiled
    monkeypatch.setattr(rps3_kernels, "numpy_tan", lambda *a: ran.append("tan") or spy(*a))
    monkeypatch.setattr(ABC, "_advance_compiled", lambda *a: ran.append("advance") or spy_advance(*a))
    several = algorithm in ("abc", "gabc") and "stop_at_target" not in options
    for seed in (3, 4):
        got = {}
        for mode in (None, "numpy"):
            if mode is None:
                monkeypatch.delenv(numerics_path.ENV, raising=False)
            else:
                monkeypatch.setenv(numerics_path.ENV, mode)
            ran.clear()
            got[mode] = fkopt.solve(p, algorithm, population=population, iterations=100, runs=6, seed=seed,
                                    params=params, **options)
            assert bool(ran) == (mode is None)           # the compiled iteration ran by default only
            assert ("advance" in ran) == (several and mode is None)
        fused, ref = got[None], got["numpy"]
        for name in ("x", "fitness", "history", "evaluation_history", "evaluations", "iterations_done"):
            assert np.array_equal(getattr(fused, name), getattr(ref, name)), (name, seed)
        for a, b in zip(fused.events, ref.events):
            assert np.array_equal(a, b)
    if "target" in options:                                # some runs froze at the target on the way
        assert (fused.iterations_done < 100).any()
    kind = PSO._compiled_step(p) if algorithm == "pso" else ABC()._compiled_iteration(p)
    assert kind is None                                    # FKOPT_NUMERICS=numpy (still set): the reference


@pytest.mark.parametrize("algorithm,params", [("abc", {"limit": 3}), ("gabc", {}), ("gabc", {"rule": "zhu2010"})])
def test_compiled_abc_without_numpys_tan_loop_takes_one_iteration_per_call_with_the_same_bits(monkeypatch, algorithm,
                                                                                            params):
    """Where numpy's tan loop cannot be called from compiled code (numpy_tan_address None), ABC
    and GABC offer no compiled_advance and run one compiled iteration per call around np.tan
    from Python: the numpy path's runs all the same, snapshots and best points per iteration too;
    with the loop, several iterations per call give the same records."""
    from fkopt.algorithms.abc import ABC
    m = fkopt.mechanism("3-rps")
    targets = m.bounds[:, 0] + np.random.default_rng(5).random((3, 3)) * (m.bounds[:, 1] - m.bounds[:, 0])
    p_loop, p_none = (fkopt.fk_problem(m, m.ik(targets)) for _ in range(2))
    options = dict(population=10, iterations=80, runs=4, seed=2, params=params, x_history=True, snapshots=(0, 7, 80))
    got = {}
    for mode, p in (("numpy", p_none), ("loop", p_loop), ("none", p_none)):
        monkeypatch.setenv(numerics_path.ENV, "numpy" if mode == "numpy" else "auto")
        if mode == "none":
            monkeypatch.setattr(rps3_kernels, "numpy_tan_address", lambda: None)
            assert ABC().compiled_advance(p) is None and ABC()._compiled_iteration(p) is not None
        if mode == "loop":
            assert ABC().compiled_advance(p) is not None
        got[mode] = fkopt.solve(p, algorithm, **options)
    for mode in ("loop", "none"):
        for name in ("x", "fitness", "history", "evaluation_history", "x_history", "evaluations"):
            assert np.array_equal(getattr(got[mode], name), getattr(got["numpy"], name)), (mode, name)
        assert all(np.array_equal(a, b) for a, b in zip(got[mode].events, got["numpy"].events))
        assert sorted(got[mode].snapshots) == [0, 7, 80]
        assert all(np.array_equal(got[mode].snapshots[t], got["numpy"].snapshots[t]) for t in (0, 7, 80))


@pytest.mark.parametrize("algorithm", ["abc", "gabc"])
def test_compiled_abc_under_a_progress_listener_ticks_inside_the_run_with_the_same_bits(algorithm):
    """A progress bar (fkopt run) listens: the several-iteration calls then end every
    iterations/TICKS iterations so the bar moves inside a task, and the records stay the same."""
    from fkopt.algorithms.base import TICKS
    from fkopt.progress import listening
    m = fkopt.mechanism("3-rps")
    targets = m.bounds[:, 0] + np.random.default_rng(8).random((2, 3)) * (m.bounds[:, 1] - m.bounds[:, 0])
    p = fkopt.fk_problem(m, m.ik(targets))
    options = dict(population=10, iterations=90, runs=3, seed=4, x_history=True, snapshots=(0, 45, 90))
    quiet = fkopt.solve(p, algorithm, **options)
    heard = []
    with listening(heard.append):
        loud = fkopt.solve(p, algorithm, **options)
    assert len(heard) >= TICKS and heard == sorted(heard) and heard[-1] == 1.0
    for name in ("x", "fitness", "history", "evaluation_history", "x_history", "evaluations"):
        assert np.array_equal(getattr(quiet, name), getattr(loud, name)), name
    assert all(np.array_equal(quiet.snapshots[t], loud.snapshots[t]) for t in (0, 45, 90))


def test_compiled_abc_calls_again_where_the_logs_arrays_fill_up(monkeypatch):
    """The log's improvements of one several-iteration call are held in arrays of
    abc_kernels.LOG_ROOM places; made one iteration's worth, a call ends after any iteration that
    kept one, and the caller calls again on the rest of the draws: more calls, the same records."""
    from fkopt.algorithms import abc_kernels
    m = fkopt.mechanism("3-rps")
    p = fkopt.fk_problem(m, m.ik(np.array([4.0, -7.0, 480.0])))
    options = dict(population=10, iterations=60, runs=5, seed=6)
    monkeypatch.setenv(numerics_path.ENV, "numpy")
    ref = fkopt.solve(p, "gabc", **options)
    monkeypatch.setenv(numerics_path.ENV, "auto")
    for room, more in (((2, 4096), False), ((1, 0), True)):
        monkeypatch.setattr(abc_kernels, "LOG_ROOM", room)
        calls = []
        kernel = abc_kernels._iterations_kernel
        monkeypatch.setattr(abc_kernels, "_iterations_kernel",
                            lambda *a: (lambda *b: calls.append(1) or kernel(*a)(*b)))
        got = fkopt.solve(fkopt.fk_problem(m, p.joints), "gabc", **options)
        monkeypatch.setattr(abc_kernels, "_iterations_kernel", kernel)
        assert len(calls) > 10 if more else len(calls) == 1    # 5 runs: all 60 iterations' draws fit one call
        for name in ("x", "fitness", "history", "evaluation_history", "evaluations"):
            assert np.array_equal(getattr(got, name), getattr(ref, name)), (room, name)
        assert all(np.array_equal(a, b) for a, b in zip(got.events, ref.events))


def test_compiled_swarms_span_the_numpy_fitness_blocks(monkeypatch):
    """More poses per fitness call than ThreeRPS.BLOCK (here made 7): the compiled iterations cut
    their np.tan calls as the numpy fitness cuts its blocks, and the runs stay bit for bit."""
    from fkopt.mechanisms import rps3
    monkeypatch.setattr(rps3, "BLOCK", 7)
    m = fkopt.mechanism("3-rps")
    targets = m.bounds[:, 0] + np.random.default_rng(2).random((3, 3)) * (m.bounds[:, 1] - m.bounds[:, 0])
    p = fkopt.fk_problem(m, m.ik(targets))
    for algorithm, params in (("pso", {}), ("gabc", {"limit": 3})):
        got = {}
        for mode in ("auto", "numpy"):
            monkeypatch.setenv(numerics_path.ENV, mode)
            got[mode] = fkopt.solve(p, algorithm, population=10, iterations=60, runs=5, seed=9, params=params)
        for name in ("x", "fitness", "history", "evaluation_history"):
            assert np.array_equal(getattr(got["auto"], name), getattr(got["numpy"], name)), (algorithm, name)


def test_compiled_abc_iteration_only_where_it_is_the_same_algorithm(monkeypatch):
    """The compiled ABC iteration runs for fkopt's own ABC and GABC with raw selection by default
    (and under FKOPT_NUMERICS=compiled); a subclass, ``selection: karaboga`` or
    FKOPT_NUMERICS=numpy stay numpy."""
    from fkopt.algorithms.abc import ABC
    from fkopt.algorithms.gabc import GABC
    m = fkopt.mechanism("3-rps")
    p = fkopt.fk_problem(m, m.ik(np.array([9.0, 13.0, 622.0])))

    class Mine(ABC):
        name = "mine"
    for mode in ("auto", "compiled"):
        monkeypatch.setenv(numerics_path.ENV, mode)
        assert ABC()._compiled_iteration(p)[2] == 0
        assert GABC()._compiled_iteration(p)[2] == 1 and GABC(rule="zhu2010")._compiled_iteration(p)[2] == 2
        assert ABC(selection="karaboga")._compiled_iteration(p) is None
        assert Mine()._compiled_iteration(p) is None
    monkeypatch.setenv(numerics_path.ENV, "numpy")
    assert ABC()._compiled_iteration(p) is None


def _generator(seed, run):
    from fkopt.numerics.streams import run_seed_sequence
    return np.random.Generator(np.random.PCG64(run_seed_sequence(seed, run)))


@pytest.mark.parametrize("seed,rows,width,col", [(0, 1, 1, 0), (1, 3, 349, 0), (12345, 9, 1000, 7), (7, 6, 9, 8)])
def test_compiled_refill_is_generator_random_bit_for_bit_and_leaves_the_same_state(seed, rows, width, col):
    """fill_uniforms runs numpy's PCG64 and next_double on the states in one array (four runs at a
    time, then the rest): the values of Generator.random, and, written back, the same generator
    state, so a later numpy draw continues the stream; a second fill continues it too."""
    mine = [_generator(seed, k) for k in range(rows)]
    ref = [_generator(seed, k) for k in range(rows)]
    S = compiled.pcg64_states(mine)
    for _ in range(2):
        buf = np.full((rows, width), -1.0)
        compiled.fill_uniforms(buf, col, S)
        assert (buf[:, :col] == -1.0).all()                       # columns before col untouched
        for k in range(rows):
            assert np.array_equal(buf[k, col:], ref[k].random(width - col))
    compiled.store_pcg64_states(mine, S)
    for k in range(rows):
        assert mine[k].bit_generator.state == ref[k].bit_generator.state
        assert np.array_equal(mine[k].random(17), ref[k].random(17))
        assert mine[k].integers(1 << 40) == ref[k].integers(1 << 40)
    with pytest.raises(ValueError, match="PCG64 only"):
        compiled.pcg64_states([np.random.Generator(np.random.MT19937(1))])


def test_run_streams_with_many_runs_refill_compiled_with_the_numpy_paths_values(monkeypatch):
    """Above BUFFER_VALUES // CHUNK runs the refill is the compiled kernel (one call for every run),
    below it only once numba is loaded, and under FKOPT_NUMERICS=numpy the per-run numpy calls;
    every run's values are those of its own Generator.random either way, across several refills
    and a tail kept between them."""
    from fkopt.numerics import streams as streams_mod
    monkeypatch.setattr(streams_mod, "BUFFER_VALUES", 4096)   # 200 runs: refills of 256 (< CHUNK)
    runs, seed, sizes = 200, 42, (100, 3 * 70, 1, 300, 255, 600)
    got = {}
    for mode in ("auto", "numpy"):
        monkeypatch.setenv(numerics_path.ENV, mode)
        s = streams_mod.RunStreams(seed, range(runs))
        got[mode] = np.concatenate([s.uniform(n).copy() for n in sizes], axis=1)
        assert (s._fill is not None) == (mode == "auto")
        if mode == "auto":             # leaving the compiled path: the numpy refill continues the streams
            monkeypatch.setenv(numerics_path.ENV, "numpy")
            more = s.uniform(5000)
            assert s._fill is None
            assert np.array_equal(more[199], _generator(seed, 199).random(sum(sizes) + 5000)[-5000:])
    few = streams_mod.RunStreams(seed, range(3))         # few runs: numpy's calls unless numba is loaded
    monkeypatch.setenv(numerics_path.ENV, "auto")
    assert numerics_path.compiled() is compiled and few._compiled_fill() is not None
    monkeypatch.setitem(numerics_path._STATE, "module", None)
    few._fill = None
    assert few._compiled_fill() is None
    assert np.array_equal(got["auto"], got["numpy"])
    for k in (0, 1, 117, runs - 1):
        assert np.array_equal(got["auto"][k], _generator(seed, k).random(sum(sizes)))


def test_compiled_refill_reuses_a_buffer_only_when_no_view_of_it_is_alive(monkeypatch):
    """The compiled refill writes into a spare buffer again only when nothing handed out points into
    it: a view an algorithm keeps across refills keeps its values."""
    from fkopt.numerics import streams as streams_mod
    monkeypatch.setattr(streams_mod, "BUFFER_VALUES", 4096)
    monkeypatch.setenv(numerics_path.ENV, "auto")
    s = streams_mod.RunStreams(5, range(200))
    kept = s.uniform(300)                         # held through every refill below
    copy = kept.copy()
    for _ in range(10):
        s.uniform(400)                            # dropped at once: its buffer is free again
    assert np.array_equal(kept, copy)
    assert 2 <= len(s._stores) <= 4
    assert np.array_equal(s.uniform(7)[3], _generator(5, 3).random(300 + 4000 + 7)[-7:])


@pytest.mark.parametrize("arm_name", ["7dof-arm", "urdf"])
def test_quaternion_screen_is_within_the_bound_and_keeps_the_full_passes_rows(arm_name):
    """The start table's quaternion screen (7 numbers a row: position and the rotation's unit
    quaternion, fkopt.numerics.compiled_ik._screen_quaternion) on real targets -- tip frames of
    drawn joints, on and off the table's rows, rotations by pi included, where the quaternion's
    largest component changes -- is within the float32 screen's error bound of the float64
    values, and the screened lookup gives the full float64 pass's rows in the same order; a
    feature vector that is not a rotation's falls back to the 12-feature screen."""
    from fkopt.kinematics.inverse_pose import _fast_context
    from fkopt.numerics import compiled_ik as c
    arm = fkopt.mechanism(arm_name)
    ctx = _fast_context(arm, 4096, None)
    table, wf = ctx["table"], ctx["w"]
    assert table[6].shape == (7, 4096)                  # the quaternions are kept
    from scipy.spatial.transform import Rotation        # the rows' quaternions are scipy's, up to sign
    R = (ctx["Ft"][3:].T / wf).reshape(-1, 3, 3)
    ours, theirs = c._quaternions(R), Rotation.from_matrix(R).as_quat()[:, [3, 0, 1, 2]]
    assert np.abs(np.abs(np.einsum("ij,ij->i", ours, theirs)) - 1).max() < 1e-12
    rng = np.random.default_rng(11)
    lo, hi = arm.bounds[:, 0], arm.bounds[:, 1]
    frames = arm.fk_matrix(lo + rng.random((60, arm.dof)) * (hi - lo))
    half_turns = frames[:6].copy()
    for i, axis in enumerate(np.eye(3)):                # R times a half turn about x, y, z
        half_turns[i, :3, :3] = frames[i, :3, :3] @ (2 * np.outer(axis, axis) - np.eye(3))
    tq = ctx["tq"]
    on_rows = arm.fk_matrix(np.degrees(tq[:5]) if arm.angle_mask(arm.joint_units).all() else tq[:5])
    for T in np.concatenate([frames, half_turns, on_rows]):
        f = np.empty(12)
        c._table_features(np.ascontiguousarray(T[:3, 3]), np.ascontiguousarray(T[:3, :3]), wf, ctx["fmask"], f)
        v32 = np.empty(4096, np.float32)
        assert c._screen_quaternion(table, f, v32)
        v64 = ctx["norms"] - 2.0 * (ctx["Ft"].T @ f)
        nmax, ff = ctx["norms"].max(), f @ f
        bound = c.SCREEN_ROUNDOFF * (1 + nmax + 2 * np.sqrt(nmax * ff) + ff)
        assert np.abs(v32 - v64).max() <= bound / 8            # the bound with room to spare
        for k in (4, 64):
            want, got = np.empty(k, np.int64), np.empty(k, np.int64)
            c._nearest_into(table[0], table[1], f, want, np.empty(k))
            c._screen32(table, f, v32)
            c._nearest_screened(table, f, v32, got, np.empty(k))
            assert np.array_equal(want, got)
    bent = f.copy()
    bent[3] *= 1 + 1e-6                                 # not a rotation: the 12-feature screen
    assert not c._screen_quaternion(table, bent, v32)


def test_kernel_modules_are_every_module_that_compiles_kernels():
    """fkopt.numerics.jit.KERNEL_MODULES (whose files' stamps are part of every compiled kernel's
    cache key) names exactly the package's modules that use its njit."""
    from fkopt.numerics import jit
    root = Path(fkopt.__file__).parent
    using = sorted(str(p.relative_to(root)) for p in root.rglob("*.py") if "njit(" in p.read_text())
    assert sorted(jit.KERNEL_MODULES) == using


def test_a_ctrl_c_during_a_compile_is_raised_when_the_compile_has_finished():
    """A SIGINT that arrives while numba compiles a kernel (here: sent when numba's compile event
    starts) is held until the compile ends, then raised as KeyboardInterrupt: the kernel is whole
    (compiled, callable, same answer) and SIGINT's handler is Python's again. Inside the compiler
    it had left numba half done (a finaliser's traceback, a broken cache, a segmentation fault)."""
    import os
    import signal
    from numba.core import event
    from fkopt.numerics.jit import njit

    @njit
    def twice(x):
        return 2.0 * x + 0.0 * np.sin(x)

    class SendInterrupt(event.Listener):
        def on_start(self, ev):
            os.kill(os.getpid(), signal.SIGINT)

        def on_end(self, ev):
            pass

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with event.install_listener("numba:compile", SendInterrupt()):
            with pytest.raises(KeyboardInterrupt):
                twice(1.5)
        assert twice.signatures and twice(1.5) == 3.0
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, previous)


def test_interrupts_deferred_nests_and_leaves_other_threads_alone():
    """The outermost block of the main thread holds the interrupt; a nested block's end does not
    raise it; a block in another thread changes no handler (Python allows that in the main thread
    only)."""
    import os
    import signal
    import threading
    from fkopt.numerics.jit import interrupts_deferred
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        reached = []
        with pytest.raises(KeyboardInterrupt):
            with interrupts_deferred():
                with interrupts_deferred():
                    os.kill(os.getpid(), signal.SIGINT)
                    sum(range(1000))           # the handler runs here: it holds the interrupt
                reached.append("inner block ended")
        assert reached == ["inner block ended"]
        errors = []

        def elsewhere():
            try:
                with interrupts_deferred():
                    pass
            except Exception as err:       # noqa: BLE001 -- reported below
                errors.append(err)
        t = threading.Thread(target=elsewhere)
        t.start()
        t.join()
        assert errors == [] and signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, previous)


def test_a_second_ctrl_c_during_a_compile_is_raised_at_once():
    """Someone who presses Ctrl-C twice during a long compile is not kept waiting."""
    import os
    import signal
    from fkopt.numerics.jit import interrupts_deferred
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        reached = []
        with pytest.raises(KeyboardInterrupt):
            with interrupts_deferred():
                os.kill(os.getpid(), signal.SIGINT)
                sum(range(1000))
                reached.append("held")
                os.kill(os.getpid(), signal.SIGINT)
                sum(range(1000))
                reached.append("not reached")
        assert reached == ["held"] and signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, previous)


def test_interrupts_deferred_puts_the_handler_back_when_a_pending_handler_raises(monkeypatch):
    """``signal.signal`` runs the handlers of pending signals before it swaps: one that raises (another
    library's alarm) must not leave the holding handler in place, which would swallow every later Ctrl-C."""
    import signal
    from fkopt.numerics.jit import interrupts_deferred
    real = signal.signal
    previous = real(signal.SIGINT, signal.default_int_handler)
    calls = []

    def swap(signum, handler):
        calls.append(handler)
        if handler is signal.default_int_handler and len(calls) == 2:   # the first swap back
            raise TimeoutError("another handler's alarm")
        return real(signum, handler)
    monkeypatch.setattr(signal, "signal", swap)
    try:
        with pytest.raises(TimeoutError):
            with interrupts_deferred():
                pass
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler and len(calls) == 3
    finally:
        real(signal.SIGINT, previous)


@pytest.mark.parametrize("k", [1, 4, 64])
def test_screened_nearest_rows_are_the_full_passes_rows_ties_included(k):
    """The compiled one-pose IK's start-table lookup (float32 screen, then float64 distances of
    the rows the screen cannot rule out) gives the rows of the float64 pass over every row, in
    the same order: on an arm's real table, with exact duplicate rows (ties go to the lower row),
    near-ties one ulp apart, masked-out features and targets on and off the table's rows."""
    from fkopt.kinematics.inverse_pose import _fast_context
    from fkopt.numerics import compiled_ik as c
    arm = fkopt.mechanism("7dof-arm")
    ctx = _fast_context(arm, 4096, None)
    F = ctx["Ft"].T.copy()
    F[100] = F[7]                                       # exact ties
    F[200] = np.nextafter(F[7], np.inf)                 # a near-tie
    F[300:310] = F[310:320]
    norms = np.einsum("ij,ij->i", F, F)
    table = c.start_screen(np.ascontiguousarray(F.T), norms)
    rng = np.random.default_rng(5)
    targets = [F[7], F[310], F[200] * (1 + 1e-12)] + [F[i] + rng.normal(scale=s, size=12)
                                                      for i, s in zip(rng.integers(0, len(F), 40), np.geomspace(1e-9, 1, 40))]
    for f in targets:
        for mask in (np.ones(12), np.r_[np.ones(3), np.zeros(9)], np.r_[np.zeros(3), np.ones(9)]):
            fm = np.ascontiguousarray(f * mask)
            want, got = np.empty(k, np.int64), np.empty(k, np.int64)
            c._nearest_into(table[0], table[1], fm, want, np.empty(k))
            v32 = np.empty(len(F), np.float32)
            c._screen32(table, fm, v32)
            c._nearest_screened(table, fm, v32, got, np.empty(k))
            assert np.array_equal(want, got), (k, mask)
