"""``fkopt.InverseSolver``: the prepared one-pose IK of a control loop. Held to recorded one-pose
answers of ``fkopt.inverse`` (tests/inverse_bits/one_pose.json, by tests/inverse_bits/record.py:
first at commit 255c592, before the solver existed; every arm re-recorded when issue 38 changed
the defaults, damping 5e-4, the stall test and 20 iterations, as record.py says), bit for bit, on a DH arm, URDF
arms and MJCF arms, through the solver and ``inverse`` on the default path and the Python
reference alike; bad targets are one line; options are validated once, when it is made."""
import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pytest

import fkopt
from fkopt.kinematics import solvers as kinematics
from fkopt.errors import FkoptError
from fkopt.mechanisms.urdf import example_robot, example_robots_folder
from fkopt.numerics import InverseOptions
from fkopt.run import provenance

HERE = Path(__file__).parent / "inverse_bits"
sys.path.insert(0, str(HERE))
from cases import arms, calls  # noqa: E402

RECORDED = json.loads((HERE / "one_pose.json").read_text())
#: Bit for bit on the platform that recorded them (fkopt.run.provenance's fingerprint); on another
#: platform numpy's SIMD kernels may round the targets' FK in the last bits, so the answers follow
#: the cross-platform rule: the same verdict, restarts and Jacobian evaluations, joints within
#: JOINT_ATOL (deg or m) -- the last-digit differences the recorded solves can show.
RECORDED_ON = json.loads((HERE / "platform.json").read_text())["fingerprint"]
JOINT_ATOL = 1e-9
HAVE_MUJOCO = importlib.util.find_spec("mujoco") is not None


def _arms(tmp_path_factory):
    f = tmp_path_factory.mktemp("mjcf") / "anchored.xml" if HAVE_MUJOCO else None
    if not HAVE_MUJOCO:
        pytest.skip("mujoco is not installed (the MJCF arms)")
    return arms(fkopt, example_robot, example_robots_folder, mjcf_file=f)


@pytest.fixture(scope="module")
def all_arms(tmp_path_factory):
    return _arms(tmp_path_factory)


def _split(kw):
    """(options, tol, mask, seed, start) of a recorded call's keywords."""
    kw = dict(kw)
    seed, start = kw.pop("seed"), kw.pop("start", None)
    tol, mask = kw.pop("tol", kinematics.INVERSE_TOL), kw.pop("mask", None)
    return InverseOptions(**kw), tol, mask, seed, start


def _same(got: dict, want: dict) -> bool:
    """``got == want`` on the recording platform; elsewhere the cross-platform rule above."""
    if provenance.platform_tier(RECORDED_ON) == provenance.EXACT:
        return got == want
    a, b = (np.frombuffer(bytes.fromhex(d["joints"])) for d in (got, want))
    rest = ("restarts", "evaluations", "solved")
    return all(got[k] == want[k] for k in rest) and a.shape == b.shape and bool(np.allclose(a, b, rtol=0,
                                                                                           atol=JOINT_ATOL))


def _bits(r):
    return {"joints": np.asarray(r.joints, dtype=float).tobytes().hex(), "restarts": int(r.restarts),
            "evaluations": int(r.evaluations["jacobian"]), "solved": bool(r.solved)}


@pytest.mark.parametrize("compiled", [None, False], ids=["default-path", "python-reference"])
def test_solver_and_inverse_give_the_answers_recorded_before_the_solver(all_arms, compiled):
    seen = set()
    for name, arm in all_arms:
        seen.add(name)
        for k, (target, kw) in enumerate(calls(arm, name)):
            options, tol, mask, seed, start = _split(kw)
            options = InverseOptions(**{**options.as_dict(), "compiled": compiled})
            solver = fkopt.InverseSolver(arm, options, tol=tol, mask=mask)
            want = RECORDED[name][k]
            first = _bits(solver(target, seed=seed, start=start))
            assert _same(first, want), (name, k)
            assert _bits(solver(target, seed=seed, start=start)) == first, (name, k)     # a second call alike
            assert _bits(fkopt.inverse(arm, target, options=options, tol=tol, mask=mask, seed=seed,
                                       start=start)) == first, (name, k)
    assert {"7dof-arm", "urdf", "mjcf", "mjcf-anchored"} <= seen


def test_keywords_and_the_options_object_make_the_same_solver():
    arm = fkopt.mechanism("7dof-arm")
    T = arm.fk_matrix(arm.bounds.mean(axis=1) + 10.0)
    a = kinematics.inverse_solver(arm, tol=(1e-9, 1e-9), restarts=20, table=1024)(T, seed=3)
    b = fkopt.InverseSolver(arm, InverseOptions(restarts=20, table=1024), tol=(1e-9, 1e-9))(T, seed=np.int64(3))
    c = fkopt.inverse(arm, T, tol=(1e-9, 1e-9), restarts=20, table=1024, seed=3)
    assert bool(a.solved) and _bits(a) == _bits(b) == _bits(c)
    with pytest.raises(FkoptError, match="unknown option"):
        kinematics.inverse_solver(arm, restart=20)


def test_a_batch_goes_to_inverses_batched_loop():
    arm = fkopt.mechanism("7dof-arm")
    q = arm.bounds[:, 0] + np.random.default_rng(4).random((5, arm.dof)) * np.diff(arm.bounds).ravel()
    frames = arm.fk_matrix(q)
    got = fkopt.InverseSolver(arm, tol=(1e-9, 1e-9))(frames, seed=2)
    want = fkopt.inverse(arm, frames, tol=(1e-9, 1e-9), seed=2)
    assert got.joints.shape == (5, arm.dof) and np.array_equal(got.joints, want.joints) and got.solved.all()


@pytest.mark.parametrize("target, match", [
    (np.zeros(5), r"7dof-arm target pose: expected \(\.\.\., 6\) values"),
    (np.full(6, np.nan), "values must be finite"),
    (np.diag([1.0, 1.0, 2.0, 1.0]), "needs an orthonormal rotation"),
    (np.r_[np.eye(4)[:3], [[0, 0, 1, 1]]], "last row 0 0 0 1"),
    (np.array([[1.0, 0, 0, np.inf], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]), "values must be finite"),
    (np.array([[1.0, 0, 0, 1e6], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]), "unreachable"),
    ("a", "target pose"),
])
def test_a_bad_target_is_one_line(target, match):
    solver = fkopt.InverseSolver("7dof-arm")
    with pytest.raises(FkoptError, match=match) as err:
        solver(target)
    assert "\n" not in str(err.value)


def test_a_bad_seed_is_one_line():
    solver = fkopt.InverseSolver("7dof-arm")
    with pytest.raises(FkoptError, match="seed: expected an integer") as err:
        solver(fkopt.mechanism("7dof-arm").fk_matrix(np.zeros(7)), seed="x")
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("options, match", [
    ({"restarts": -1}, "restarts: expected an integer >= 0"),
    ({"starts": 0}, "starts: expected an integer >= 1"),
    ({"table": 2.5}, "table: expected an integer >= 0"),
    ({"damping": 0.0}, "damping: expected a number > 0"),
    ({"up": float("nan")}, "up: expected a number > 0"),
    ({"orientation_scale": -1.0}, "orientation_scale: expected None or a number > 0"),
    ({"compiled": "yes"}, "compiled: expected None, true or false"),
    ({"exact_rotation": 2}, "exact_rotation: expected true or false"),
])
def test_bad_options_are_one_line_when_the_solver_is_made(options, match):
    with pytest.raises(FkoptError, match=match) as err:
        fkopt.InverseSolver("7dof-arm", InverseOptions(**options))
    assert "\n" not in str(err.value)
    with pytest.raises(FkoptError, match="expected fkopt.numerics.InverseOptions"):
        fkopt.InverseSolver("7dof-arm", {"restarts": 3})
    with pytest.raises(FkoptError, match="tol"):
        fkopt.InverseSolver("7dof-arm", tol=(0.0, 1e-6))


def test_options_are_validated_and_prepared_once_not_per_call(monkeypatch):
    arm = fkopt.mechanism("7dof-arm")
    T = arm.fk_matrix(arm.bounds.mean(axis=1) + 5.0)
    counts = {"validated": 0, "prepare": 0}
    validated, prepare = InverseOptions.validated, fkopt.InverseSolver._prepare

    def count(key, f):
        def wrapped(self, *a):
            counts[key] += 1
            return f(self, *a)
        return wrapped

    monkeypatch.setattr(InverseOptions, "validated", count("validated", validated))
    monkeypatch.setattr(fkopt.InverseSolver, "_prepare", count("prepare", prepare))
    solver = fkopt.InverseSolver(arm, tol=(1e-9, 1e-9))
    first = solver(T, seed=1)
    for s in range(5):
        assert bool(solver(T, seed=s).solved)
    assert counts == {"validated": 1, "prepare": 1}
    # the arm's limits changed under the solver: it prepares again, as inverse would
    arm.bounds = arm.bounds.copy()
    arm.bounds[0] = (-100.0, 100.0)
    r = solver(T, seed=1)
    assert counts["prepare"] == 2 and arm.bounds[0, 0] <= r.joints[0] <= arm.bounds[0, 1]
    assert _bits(r) == _bits(fkopt.inverse(arm, T, tol=(1e-9, 1e-9), seed=1))
    assert first.joints.shape == r.joints.shape


def test_the_control_loop_example_of_docs_robots_runs(capsys):
    """docs/robots.md's 1 kHz loop, shortened to 20 ticks (its timing is not asserted)."""
    text = (Path(__file__).parents[1] / "docs" / "robots.md").read_text(encoding="utf-8")
    code = text.split("### A prepared solver for a control loop")[1].split("```python\n")[1].split("```")[0]
    assert "ticks, late, solved = 1e-3, 1000, 0, 0" in code
    exec(compile(code.replace("1e-3, 1000, 0, 0", "1e-3, 20, 0, 0"), "docs/robots.md (control loop)", "exec"), {})
    assert "20 of 20 ticks solved" in capsys.readouterr().out


def test_the_path_is_chosen_when_the_solver_is_made_and_inverse_follows_the_switch(monkeypatch):
    """FKOPT_NUMERICS=numpy when a solver is made: it runs the Python reference (no kernel bound);
    fkopt.inverse keys its cached solvers on the switch, so it follows a change between calls --
    and both paths give the same bits."""
    from fkopt.numerics import path as numerics_path
    arm = fkopt.mechanism("7dof-arm")
    T = arm.fk_matrix(arm.bounds.mean(axis=1) + 7.0)
    monkeypatch.setenv(numerics_path.ENV, "numpy")
    slow = fkopt.InverseSolver(arm, tol=(1e-9, 1e-9))
    assert slow._kernel is None
    a = fkopt.inverse(arm, T, tol=(1e-9, 1e-9), seed=2)
    pytest.importorskip("numba")
    monkeypatch.setenv(numerics_path.ENV, "auto")
    fast = fkopt.InverseSolver(arm, tol=(1e-9, 1e-9))
    assert fast._kernel is not None
    b = fkopt.inverse(arm, T, tol=(1e-9, 1e-9), seed=2)
    assert _bits(a) == _bits(b) == _bits(slow(T, seed=2)) == _bits(fast(T, seed=2))


@pytest.mark.parametrize("options", [{"rest": 0.1}, {"exact_rotation": True}])
def test_options_without_a_one_pose_loop_go_to_inverses_batched_loop(options):
    arm = fkopt.mechanism("7dof-arm")
    T = arm.fk_matrix(arm.bounds.mean(axis=1) + 7.0)
    got = fkopt.InverseSolver(arm, InverseOptions(**options))(T, seed=1)
    want = fkopt.inverse(arm, T, seed=1, **options)
    assert got.joints.shape == (7,) and bool(got.solved) and np.array_equal(got.joints, want.joints)


def test_inverse_checks_its_options_alike_for_one_pose_and_a_batch():
    arm = fkopt.mechanism("7dof-arm")
    frames = arm.fk_matrix(np.stack([arm.bounds.mean(axis=1)] * 2))
    for target in (frames[0], frames):
        with pytest.raises(FkoptError, match="inverse options damping: expected a number > 0"):
            fkopt.inverse(arm, target, damping=-1.0)
        with pytest.raises(FkoptError, match="inverse options restarts"):
            fkopt.inverse(arm, target, options=InverseOptions(restarts=-2))
        for stall in (-0.1, 1.5, float("nan"), True):
            with pytest.raises(FkoptError, match="inverse options stall: expected a number >= 0"):
                fkopt.inverse(arm, target, stall=stall)
    # stall 0 is the loop without the test, 1 a test no |r|^2 meets (it never rises): both the same answers
    a, b = (fkopt.inverse(arm, frames, stall=s_, seed=3) for s_ in (0.0, 1.0))
    assert np.array_equal(a.joints, b.joints) and np.array_equal(a.restarts, b.restarts)
