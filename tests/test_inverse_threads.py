"""``fkopt.inverse``'s ``threads``: the threads that share a batch's rows on the compiled path
(:func:`fkopt.numerics.compiled_ik.inverse_rows`). Every row's answer depends only on its pose,
its start and the seed, so any number of threads gives the same bytes; the option is bounded,
and it really runs that many threads (the batch's rows shared, each row once)."""
import threading

import numpy as np
import pytest

import fkopt
from fkopt.errors import FkoptError
from fkopt.numerics import InverseOptions
from fkopt.numerics import compiled_ik
from fkopt.numerics import path as numerics_path


def _batch(arm, n, seed):
    q = arm.bounds[:, 0] + np.random.default_rng(seed).random((n, arm.dof)) * np.diff(arm.bounds).ravel()
    return arm.fk_matrix(q)


def _bits(res):
    return b"".join(np.ascontiguousarray(a).tobytes() for a in (
        res.joints, res.position_error, res.rotation_error, res.solved, res.restarts,
        res.evaluations["residual"], res.evaluations["jacobian"]))


@pytest.fixture
def compiled_path(monkeypatch):
    monkeypatch.setenv(numerics_path.ENV, "auto")
    if numerics_path.compiled_ik(None) is None:
        pytest.skip("the compiled path cannot run here")


@pytest.mark.parametrize("options", [{}, {"tol": (1e-9, 1e-9), "restarts": 40}, {"start": "mid"}, {"mask": "x,y,z"}])
def test_any_number_of_threads_gives_the_same_bytes(compiled_path, options):
    """A batch of 150 rows (some needing many restarts at 1e-9) on 1, 2, 3 and 7 threads and the
    default: every array of the answer the same bytes; a start and a task mask included."""
    arm = fkopt.mechanism("7dof-arm")
    T = _batch(arm, 150, 11)
    kw = dict(options, seed=5)
    if kw.get("start") == "mid":
        kw["start"] = arm.bounds.mean(axis=1) + 3.0
    want = fkopt.inverse(arm, T, threads=1, **kw)
    if "mask" not in options:                           # position only: every row solved from its first start
        assert want.restarts.max() > 0                   # rows that restart, not only first-start answers
    for threads in (2, 3, 7, None):
        assert _bits(fkopt.inverse(arm, T, threads=threads, **kw)) == _bits(want), threads
    # the same through an options object and a prepared solver
    o = InverseOptions(threads=2, **{k: v for k, v in options.items() if k == "restarts"})
    solver = fkopt.InverseSolver(arm, o, tol=kw.get("tol", (1e-6, 1e-6)), mask=kw.get("mask"))
    if "start" not in kw:
        assert _bits(solver(T, seed=5)) == _bits(want)


def test_threads_share_the_rows_each_row_once(compiled_path, monkeypatch):
    """threads=3 runs the compiled loop on 3 threads (this one and two more), threads=1 on this
    thread alone, and a batch below THREAD_ROWS on this thread whatever ``threads`` says; the
    answers (each row's own) come out in row order either way."""
    arm = fkopt.mechanism("7dof-arm")
    T = _batch(arm, 200, 3)
    kernel = compiled_ik._inverse_rows
    ran = []

    def spy(*args):
        ran.append(threading.current_thread())          # the objects, kept: an ended thread's ident is reused
        return kernel(*args)
    monkeypatch.setattr(compiled_ik, "_inverse_rows", spy)
    one = fkopt.inverse(arm, T, threads=1)
    assert ran == [threading.current_thread()]
    ran.clear()
    three = fkopt.inverse(arm, T, threads=3)
    assert len(ran) == 3 and len(set(map(id, ran))) == 3 and threading.current_thread() in ran
    assert _bits(one) == _bits(three)
    singles = [fkopt.inverse(arm, T[k], seed=0) for k in (0, 77, 199)]
    assert [s.joints.tobytes() for s in singles] == [three.joints[k].tobytes() for k in (0, 77, 199)]
    ran.clear()
    fkopt.inverse(arm, T[:compiled_ik.THREAD_ROWS - 1], threads=8)
    assert ran == [threading.current_thread()]


def test_an_error_in_a_helper_thread_reaches_the_caller(compiled_path, monkeypatch):
    arm = fkopt.mechanism("7dof-arm")
    T = _batch(arm, 100, 4)
    kernel = compiled_ik._inverse_rows
    main = threading.get_ident()

    def failing(*args):
        if threading.get_ident() != main:
            raise RuntimeError("helper failed")
        return kernel(*args)
    monkeypatch.setattr(compiled_ik, "_inverse_rows", failing)
    with pytest.raises(RuntimeError, match="helper failed"):
        fkopt.inverse(arm, T, threads=2)


@pytest.mark.parametrize("threads", [0, -1, 257, 1.5, "2", True])
def test_threads_out_of_bounds_is_one_line(threads):
    arm = fkopt.mechanism("7dof-arm")
    T = _batch(arm, 2, 1)
    with pytest.raises(FkoptError, match=r"inverse options threads: expected an integer >= 1 and <= 256"):
        fkopt.inverse(arm, T, threads=threads)
    with pytest.raises(FkoptError, match=r"threads: expected an integer >= 1 and <= 256"):
        fkopt.InverseSolver(arm, InverseOptions(threads=threads))


def test_the_numpy_path_takes_threads_and_runs_on_this_thread(monkeypatch):
    """``FKOPT_NUMERICS=numpy``: the vectorised batch loop, the same answers for any ``threads``."""
    monkeypatch.setenv(numerics_path.ENV, "numpy")
    arm = fkopt.mechanism("7dof-arm")
    T = _batch(arm, 70, 9)
    assert _bits(fkopt.inverse(arm, T, threads=1)) == _bits(fkopt.inverse(arm, T, threads=4))
