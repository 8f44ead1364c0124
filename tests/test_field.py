"""kinbench v3: the field's IK solvers (fkopt.adapters.field) and physical verification
(fkopt.kinbench.physical), on the UR5 and Panda of example-robot-data."""
import numpy as np
import pytest

from fkopt.kinbench.physical import LADDER, ik_verdicts, rung_label

pytestmark = pytest.mark.external


def arm(name):
    from fkopt.mechanisms import urdf
    if urdf.example_robots_folder() is None:
        pytest.skip("example-robot-data is not installed")
    return urdf.example_robot(name)


def targets(m, n, seed):
    rng = np.random.default_rng(seed)
    q = m.bounds[:, 0] + rng.random((n, m.dof)) * (m.bounds[:, 1] - m.bounds[:, 0])
    return q, m.fk_matrix(q)


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_verification_matches_pinocchio_fk(name):
    """Errors computed by kinbench equal those from pinocchio's own URDF reader and FK."""
    pin = pytest.importorskip("pinocchio")
    m = arm(name)
    q, T = targets(m, 10, 1)
    q2 = q + np.random.default_rng(2).normal(0, 0.5, q.shape)           # wrong answers, deg
    model = pin.buildModelFromUrdf(str(m.path))
    data = model.createData()
    fid = model.getFrameId(m.tip_link)
    idx = [model.joints[model.getJointId(n)].idx_q for n in m.joint_names]
    v = ik_verdicts(m, q2, T)
    for k in range(len(q)):
        x = pin.neutral(model)
        x[idx] = np.radians(q2[k])
        pin.framesForwardKinematics(model, data, x)
        F = data.oMf[fid]
        assert v["position_m"][k] == pytest.approx(np.linalg.norm(F.translation - T[k, :3, 3]), abs=1e-12)
        ang = np.linalg.norm(pin.log3(F.rotation.T @ T[k, :3, :3]))
        assert v["rotation_rad"][k] == pytest.approx(ang, abs=1e-9)


def test_wrong_or_out_of_limit_answer_is_a_failure_whatever_is_claimed():
    m = arm("ur5")
    q, T = targets(m, 4, 3)
    answers = q.copy()
    answers[1, 0] += 0.1                        # 0.1 deg off: fails the tight rungs
    answers[2] = np.nan                         # no answer
    answers[3, 2] = m.bounds[2, 1] + 1e-6       # outside the elbow's limit
    T[3] = m.fk_matrix(answers[3])              # ... although its pose is exact
    v = ik_verdicts(m, answers, T)
    assert v["success"][0].all()
    assert v["success"][1, 0] and not v["success"][1, 2:].any()
    assert not v["success"][2].any() and np.isinf(v["position_m"][2])
    assert not v["in_limits"][3] and not v["success"][3].any()
    assert [rung_label(r) for r in LADDER] == ["5mm_0.05rad", "1mm_0.01rad", "1e-05m_1e-05rad", "1e-08m_1e-08rad"]


#: Share of 10 random poses each wrapper must solve at (1 mm, 0.01 rad) within its timeout (s);
#: measured on this machine: TRAC-IK 5 ms 51-90 %, ikpy 20 ms 50-60 % (one start is ~25 ms). The
#: timeouts are wall-clock and these tests check answers, not speed (the board measures speed): the
#: restart loops get 0.1 s (at load 15 on 2 cores pin-clik solved 6 of 10 UR5 poses in 20 ms).
JACOBIAN_FLOOR = {"tracik": (0.02, 0.7), "rtb-ik_LM": (0.02, 0.7), "rtb-ik_NR": (0.02, 0.7),
                  "pin-clik": (0.1, 0.7), "ikpy": (0.1, 0.5), "optik": (0.02, 0.7), "pink": (0.1, 0.5)}


def _needs(solver):
    from fkopt.registry import SOLVERS
    module = {"pytracik": "pytracik", "roboticstoolbox-python": "roboticstoolbox", "pin": "pinocchio",
              "optik-py": "optik", "pin-pink": "pink", "pytorch-kinematics": "pytorch_kinematics"}
    package = SOLVERS[solver].package
    pytest.importorskip(module.get(package, package))


@pytest.mark.parametrize("solver", list(JACOBIAN_FLOOR))
@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_field_solver_answers_verified(solver, name):
    """Each wrapper answers reachable in-limit poses; kinbench's own check passes the loose rungs
    on most of them (TRAC-IK misses some: its answers are its own, verified, not trusted)."""
    from fkopt.adapters.field import solve
    from fkopt.registry import clock_solver as make_ik
    _needs(solver)
    timeout, floor = JACOBIAN_FLOOR[solver]
    m = arm(name)
    _, T = targets(m, 10, 4)
    a = solve(make_ik(solver, m, timeout=timeout, rng=np.random.default_rng(5)), T)
    assert a.joints.shape == (10, m.dof) and a.seconds.shape == (10,) and (a.seconds > 0).all()
    v = ik_verdicts(m, a.joints, T)
    assert v["success"][:, 1].mean() >= floor
    assert (v["success"][:, 1] <= v["in_limits"]).all()
    assert a.settings["timeout_s"] == timeout


def stored(name):
    """A kinbench arm from its stored copy (configs/suites/robots), URDF or MJCF."""
    import fkopt
    from fkopt.kinbench.robots import ARMS
    from pathlib import Path
    a = next(a for a in ARMS if a.name == name)
    suites = Path(__file__).resolve().parents[1] / "configs" / "suites"
    return fkopt.mechanism(a.format, file=str(suites / a.file), base=a.base, tip=a.tip)


@pytest.mark.parametrize("solver", list(JACOBIAN_FLOOR))
def test_field_solvers_read_an_mjcf_arm_through_the_written_urdf(solver):
    """MJCF arms reach the URDF-only packages through the URDF written from fkopt's chain; their
    answers pass kinbench's own check (floor 0.4 at (1 mm, 0.01 rad): measured here, pin-clik
    solves 50 % of these UR5e poses in 20 ms; on the UR5 it solves 95 % through the robot's file
    and through the written URDF alike, so the shortfall is the arm's, not the written file's)."""
    pytest.importorskip("mujoco")
    from fkopt.adapters.field import solve
    from fkopt.registry import clock_solver as make_ik
    _needs(solver)
    timeout, floor = JACOBIAN_FLOOR[solver]
    m = stored("ur5e-mj")
    _, T = targets(m, 10, 4)
    w = make_ik(solver, m, timeout=timeout, rng=np.random.default_rng(5))
    assert w.settings["urdf"].startswith("written from fkopt's chain")
    v = ik_verdicts(m, solve(w, T).joints, T)
    assert v["success"][:, 1].mean() >= min(floor, 0.4)


def test_rtb_reads_the_written_urdf_where_it_misreads_the_robots_file():
    """rtb's FK of iCub's own file is 1.5 m off fkopt's and pinocchio's; rtb reads only the URDF
    written from fkopt's chain (issue 42), and reads iCub's right."""
    pytest.importorskip("roboticstoolbox")
    from fkopt.registry import clock_solver as make_ik
    m = stored("icub-left")
    w = make_ik("rtb-ik_LM", m, timeout=0.02, rng=np.random.default_rng(1))
    assert w.settings["urdf"].startswith("written")
    q, T = targets(m, 3, 2)
    assert np.abs(w.ets.fkine(np.radians(q[0])).A - T[0]).max() < 1e-12


@pytest.mark.parametrize("solver", ["cma-es", "scipy-lbfgsb", "nevergrad-ngopt"])
def test_black_box_wrappers_improve_on_their_start_and_never_leave_the_limits(solver):
    """The black-box optimisers rarely reach a rung within milliseconds (the clock track says
    so); here: answers inside the limits, their objective (|dp|^2 + angle^2) under a quarter of
    the median at random joints, and a claim of success is one kinbench confirms."""
    from fkopt.adapters.field import pose_objective
    from fkopt.adapters.field import solve
    from fkopt.registry import clock_solver as make_ik
    _needs(solver)
    m = arm("ur5")
    _, T = targets(m, 2, 6)
    a = solve(make_ik(solver, m, timeout=0.25, rng=np.random.default_rng(7)), T)
    v = ik_verdicts(m, a.joints, T)
    assert v["in_limits"].all()
    lo, hi = m.bounds[:, 0], m.bounds[:, 1]
    for k in range(2):
        f = pose_objective(m, T[k])
        random = np.median(f(np.radians(lo + np.random.default_rng(k).random((200, m.dof)) * (hi - lo))))
        assert f(np.radians(a.joints[k]))[0] < 0.25 * random
    # a claim (objective <= RUNG^2) is one kinbench confirms at every rung down to the board's 1e-5
    assert (v["success"][a.claimed][:, :3].all(axis=-1)).all()


def test_least_squares_fk_answers_are_judged_in_both_assembly_modes():
    """scipy least_squares on Dietmaier's 6-6 platform from random starts: every answer it
    accepts solves the legs; some are the generating pose, some another assembly mode, and
    fk_verdicts tells them apart with fkopt's own inverse map."""
    import fkopt
    from fkopt.adapters.field.scipy_fk import LeastSquaresFK
    from fkopt.kinbench.physical import fk_verdicts
    m = fkopt.mechanism("6-sps")
    rng = np.random.default_rng(0)
    x = m.bounds.mean(1) + rng.normal(0, 1, (5, 6)) * 0.02 * (m.bounds[:, 1] - m.bounds[:, 0])
    legs = m.ik(x)
    solver = LeastSquaresFK(m, timeout=0.05, rng=np.random.default_rng(1))
    out = [solver.solve1(L) for L in legs]
    poses = np.array([p for p, _ in out])
    v = fk_verdicts(m, poses, x, legs)
    claimed = np.array([c for _, c in out])
    assert claimed.sum() >= 3
    assert (v["leg_residual"][claimed] <= 1e-10).all()
    assert (v["success"][claimed, 2] | v["other_mode"][claimed, 2]).all()
    assert v["success"][:, 2].any() and v["other_mode"][:, 2].any()
    exact = fk_verdicts(m, x, x, legs)
    assert exact["success"].all() and not exact["other_mode"].any()


def test_clock_track_with_the_field_reference():
    """The clock track on the Panda with rtb ik_LM as the reference: one run per timeout for
    TRAC-IK (wall-clock limit), one run for fkopt.inverse and rtb (none), ratios to rtb's time."""
    _needs("tracik")
    _needs("rtb-ik_LM")
    from fkopt.kinbench.clock import clock_board, run_clock
    m = arm("panda")
    q, _ = targets(m, 5, 8)
    a = run_clock(m, "panda", q, ["fkopt.inverse", "tracik"], seed=2)
    assert sorted(a.groupby("solver").size().items()) == [("fkopt.inverse", 5), ("rtb-ik_LM", 5), ("tracik", 15)]
    assert sorted(a.loc[a.solver == "tracik", "given_timeout_ms"].unique()) == [1.0, 5.0, 20.0]
    b = clock_board(a)
    assert len(b) == 9 and set(b["entry"]) == {"organiser", "outside"}
    assert (b.loc[b.solver == "rtb-ik_LM", "time_ratio_median"] >= 1.0).all()     # first call / best of 3
    # judged at the 20 ms timeout: at 1 ms a success also needs the call inside 1 ms, which a loaded
    # shared machine does not promise (the board measures time; this test checks the track's shape)
    assert (b.loc[(b.solver == "fkopt.inverse") & (b.timeout_ms == 20.0), "success_1e-05m_1e-05rad"] == 1.0).all()


@pytest.mark.parametrize("name", ["pr2-left", "tiago", "talos-left"])
def test_rtb_chain_below_a_moving_joint_has_the_chains_joints_only(name):
    """rtb's robot.ets(base, tip) takes the joint into base too when it moves (PR2's and TIAGo's
    torso lift, Talos's torso); the adapter's ETS has the chain's joints, with fkopt's FK."""
    pytest.importorskip("roboticstoolbox")
    from fkopt.adapters.field import arm_urdf
    from fkopt.adapters.field.rtb import chain_ets
    m = arm(name)
    ets, _ = chain_ets(arm_urdf(m))
    q, T = targets(m, 3, 6)
    assert ets.n == m.dof
    for k in range(3):
        assert np.abs(ets.fkine(np.radians(q[k])).A - T[k]).max() < 1e-12


def test_eaik_gives_every_analytic_solution_and_the_board_one_inside_the_limits():
    """EAIK (analytic, by subproblem decomposition) on the UR5: every pose of 10 random in-limit
    configurations has at most 8 solutions (the UR family's bound); each exact one in the limits reproduces the target by
    fkopt's FK to 1e-9, the generating configuration is among them (up to whole turns), and the
    board's one answer is one of them."""
    pytest.importorskip("eaik")
    from fkopt.registry import clock_solver as make_ik
    m = stored("ur5")
    q, T = targets(m, 10, 7)
    w = make_ik("eaik", m, timeout=0.02, rng=np.random.default_rng(0))
    for k in range(len(q)):
        s = w.solutions(T[k])
        exact = ~s.least_squares & s.in_limits
        assert 1 <= len(s.joints) <= 8 and exact.any()
        e = ik_verdicts(m, s.joints[exact], np.repeat(T[k][None], exact.sum(), axis=0))
        assert (e["position_m"] < 1e-9).all() and (e["rotation_rad"] < 1e-9).all()
        turns = (s.joints[exact] - q[k] + 180.0) % 360.0 - 180.0
        assert np.abs(turns).max(axis=1).min() < 1e-6
        one, claimed = w.solve1(T[k])
        assert claimed and np.abs(s.joints[exact] - one).max(axis=1).min() == 0.0


@pytest.mark.parametrize("name, why", [("panda", "7 joints: EAIK solves 1-6R")])
def test_eaik_is_not_applicable_to_an_arm_it_cannot_decompose(name, why):
    """A 7-joint arm is a "not applicable: why" cell, not a zero: make_ik raises NotApplicable."""
    pytest.importorskip("eaik")
    from fkopt.adapters.field import NotApplicable
    from fkopt.registry import clock_solver as make_ik
    with pytest.raises(NotApplicable, match=why):
        make_ik("eaik", stored(name), timeout=0.02, rng=np.random.default_rng(0))


def test_optik_is_not_applicable_to_a_prismatic_joint_which_would_abort_the_process():
    """OptIK 0.5's Jacobian panics on a prismatic joint and the panic aborts Python: the TIAGo's
    torso lift makes it a "not applicable" cell before any call."""
    pytest.importorskip("optik")
    from fkopt.adapters.field import NotApplicable
    from fkopt.registry import clock_solver as make_ik
    with pytest.raises(NotApplicable, match="prismatic joint torso_lift_joint"):
        make_ik("optik", stored("tiago-torso"), timeout=0.02, rng=np.random.default_rng(0))


def test_optik_reads_the_written_urdf_with_its_inner_fixed_joints_folded():
    """OptIK's FK of the written UR5 is 1.0 off past the fixed joint between wrist_2 and wrist_3;
    with it folded into wrist_3 (fold_fixed) its FK is fkopt's everywhere."""
    optik = pytest.importorskip("optik")
    from fkopt.adapters.field import arm_urdf
    from fkopt.adapters.field.optik import fold_fixed
    m = stored("ur5")
    u = arm_urdf(m)
    q, T = targets(m, 5, 11)
    for text, close in ((u.text, False), (fold_fixed(u.text), True)):
        with u.as_file(text) as path:
            robot = optik.Robot.from_urdf_file(str(path), u.base_link, u.tip_link)
        err = max(np.abs(np.asarray(robot.fk(np.radians(x))) - t).max() for x, t in zip(q, T))
        assert (err < 1e-12) == close, err


def test_pytorch_kinematics_answers_a_batch_judged_by_kinbench():
    """pytorch-kinematics' batched IK (the [torch] extra) answers 20 UR5 poses in one call; kinbench
    confirms most at the board's rung (measured here: 100 %)."""
    pytest.importorskip("torch", reason="torch is in the [torch] extra, outside [test]")
    pytest.importorskip("pytorch_kinematics", reason="pytorch-kinematics is in the [torch] extra, outside [test]")
    from fkopt.registry import clock_solver as make_ik
    m = stored("ur5")
    _, T = targets(m, 20, 12)
    w = make_ik("pytorch-kinematics", m, timeout=0.02, rng=np.random.default_rng(3))
    q = w.solve_batch(T)
    v = ik_verdicts(m, q, T)
    assert q.shape == (20, m.dof) and v["success"][:, 2].mean() >= 0.8


# -- reproduction checks: each outside package's own published protocol, on this machine ---------

#: TRAC-IK's README (traclabs/trac_ik, "IK success and average speed", tag v1.4.6; Speed mode, eps
#: 1e-5 per component, 5 ms, seeded at the middle of the limits): its published success (%).
TRACIK_README = {"panda": 99.70, "kinova-j2s6s200": 99.78, "iiwa-mj": 99.84, "baxter-left": 99.62}


@pytest.mark.parametrize("name", list(TRACIK_README))
def test_tracik_readme_protocol_reproduces_its_published_success(name):
    """TRAC-IK's README protocol (1000 random in-limit configurations, seed at the middle of the
    limits, eps 1e-5, 5 ms, Speed; success as TRAC-IK reports it, mean time over successes) on
    the README's arms that example-robot-data carries (Panda, Jaco2 j2s6s200, Baxter; not the
    iiwa 14): within 1.5 points of the published figure. A wall-clock protocol on a busy machine
    measures the machine: judged only when the 1-minute load is below 1.5."""
    import os
    import time
    pytest.importorskip("pytracik")
    if name == "iiwa-mj":
        pytest.skip("the README's figure is for the LBR iiwa 14 R820; robosuite's iiwa is the iiwa 7 R800 "
                    "(links 0.34 / 0.40 / 0.40 m) and example-robot-data carries none")
    from fkopt.adapters.field.cores import pinned
    from fkopt.adapters.field.tracik import TracIK
    from fkopt.numerics.rotations import quaternion_xyzw1 as quat_xyzw
    load = os.getloadavg()[0]
    if load >= 1.5:
        pytest.skip(f"1-minute load {load:.2f} >= 1.5: TRAC-IK's 5 ms wall-clock protocol would measure the machine")

    class Readme(TracIK):
        EPS = 1e-5                                   # the README's eps (per twist component)
    m = stored(name)
    w = Readme(m, timeout=0.005, rng=np.random.default_rng(0))
    q, T = targets(m, 1000, 2015)
    mid = (w.lo_rad + w.hi_rad) / 2
    ok, secs = np.zeros(len(T), bool), np.zeros(len(T))
    with pinned():                                   # the whole process on one core, as the clock track
        for k in range(len(T)):
            x, y, z, qw = quat_xyzw(T[k].tolist())
            t0 = time.perf_counter()
            out = w._pt.ik(w._solver, mid, T[k, 0, 3], T[k, 1, 3], T[k, 2, 3], x, y, z, qw)
            secs[k] = time.perf_counter() - t0
            ok[k] = out[0] > 0
    rate = 100 * ok.mean()
    print(f"{name}: {rate:.2f} % (README {TRACIK_README[name]} %), mean {1e3 * secs[ok].mean():.3f} ms over "
          f"successes, load {load:.2f} -> {os.getloadavg()[0]:.2f}")
    assert abs(rate - TRACIK_README[name]) <= 1.5


def test_pinocchio_clik_example_converges_as_documented():
    """pinocchio publishes no IK solver, only its CLIK example ("Inverse kinematics (clik)",
    examples/inverse-kinematics.py: DT 0.1, damp 1e-12, eps 1e-4, IT_MAX 1000, from neutral),
    which converges on its sample manipulator towards (1, 0, 1). The example as documented
    converges; and pin-clik's loop with the example's settings (no step cap, no stall test, no
    limits) converges from the middle of the UR5's limits to a pose near it, as the example does:
    the board's settings differ only where a random start needs them (docs/kinbench.md)."""
    pin = pytest.importorskip("pinocchio")
    model = pin.buildSampleModelManipulator()
    data = model.createData()
    JOINT_ID, oMdes = 6, pin.SE3(np.eye(3), np.array([1.0, 0.0, 1.0]))
    q = pin.neutral(model)
    eps, IT_MAX, DT, damp = 1e-4, 1000, 1e-1, 1e-12
    for i in range(IT_MAX):
        pin.forwardKinematics(model, data, q)
        iMd = data.oMi[JOINT_ID].actInv(oMdes)
        err = pin.log(iMd).vector
        if np.linalg.norm(err) < eps:
            break
        J = pin.computeJointJacobian(model, data, q, JOINT_ID)
        J = -np.dot(pin.Jlog6(iMd.inverse()), J)
        v = -J.T.dot(np.linalg.solve(J.dot(J.T) + damp * np.eye(6), err))
        q = pin.integrate(model, q, v * DT)
    assert np.linalg.norm(err) < eps and i < IT_MAX - 1
    from fkopt.registry import clock_solver as make_ik
    m = stored("ur5")
    w = make_ik("pin-clik", m, timeout=1.0, rng=np.random.default_rng(0))
    mid = m.bounds.mean(axis=1)
    T = m.fk_matrix((mid + 20.0)[None])[0]
    oMdes = w._oMbase * pin.SE3(T[:3, :3].copy(), T[:3, 3].copy())
    q, err, ok = w.clik(oMdes, np.radians(mid), float("inf"), dt=0.1, damp=1e-12, eps=1e-4, it_max=1000,
                        step_max=0, stall=False, limits=False)
    assert ok and err < 1e-4


def test_ikpy_tutorial_protocol_on_baxter():
    """ikpy's quickstart protocol (its defaults: ``inverse_kinematics`` of a target position, start at
    zeros, symbolic chain) on example-robot-data's Baxter left arm: ikpy publishes no success
    figure, so the check is that its answers, judged by kinbench's FK, reach most reachable
    positions to 1 mm from its single start (docs/kinbench.md has the share measured here)."""
    pytest.importorskip("ikpy")
    import warnings
    from fkopt.registry import clock_solver as make_ik
    m = stored("baxter-left")
    w = make_ik("ikpy", m, timeout=1.0, rng=np.random.default_rng(0))
    q, T = targets(m, 30, 8)
    reached = []
    for k in range(len(T)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            x = w.chain.inverse_kinematics(T[k, :3, 3])
        F = m.fk_matrix(w.public(x[w._active])[None])[0]
        reached.append(np.linalg.norm(F[:3, 3] - T[k, :3, 3]) <= 1e-3)
    assert np.mean(reached) >= 0.6


def test_clock_pin_holds_threads_started_before_it_and_the_blas_pool():
    """The clock track's one core (fkopt/adapters/field/cores.py): a thread that existed before the
    block (as OpenBLAS's pool or a Rust package's workers do) runs on the caller's core inside it,
    the BLAS pool has one thread, and both are restored after; a thread started inside the block
    gets, after it, the affinity it would have inherited without the block."""
    import os
    import threading
    import time
    from threadpoolctl import threadpool_info
    from fkopt.adapters.field.cores import pinned
    if not hasattr(os, "sched_setaffinity") or len(os.sched_getaffinity(0)) < 2:
        pytest.skip("needs Linux affinity and two allowed cores")
    ready, stop, tid, late = threading.Event(), threading.Event(), [], None

    def worker():
        tid.append(threading.get_native_id())
        ready.set()
        stop.wait()
    t = threading.Thread(target=worker)
    t.start()
    ready.wait()
    allowed = os.sched_getaffinity(0)
    try:
        with pinned() as ok:
            assert ok
            core = os.sched_getaffinity(0)
            assert len(core) == 1 and os.sched_getaffinity(tid[0]) == core
            assert all(i["num_threads"] == 1 for i in threadpool_info() if i.get("user_api") == "blas")
            late = threading.Thread(target=worker)          # a pool a package starts inside the block
            late.start()
            while len(tid) < 2:
                time.sleep(0.001)
            assert os.sched_getaffinity(tid[1]) == core
        assert os.sched_getaffinity(0) == allowed and os.sched_getaffinity(tid[0]) == allowed
        assert os.sched_getaffinity(tid[1]) == allowed     # what it would have inherited without the block
        with pinned(whole_process=False):       # a wrapper's per-call pin: the caller's thread only
            assert len(os.sched_getaffinity(0)) == 1 and os.sched_getaffinity(tid[0]) == allowed
    finally:
        stop.set()
        t.join()
        if late is not None:
            late.join()
