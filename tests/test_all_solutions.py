"""Every IK solution of a pose: fkopt.inverse(arm, pose, solutions="all") (fkopt/kinematics/branches.py)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import fkopt
from fkopt.errors import FkoptError

SUITES = Path(__file__).resolve().parents[1] / "configs" / "suites"


def stored(name):
    from fkopt.kinbench.robots import ARMS
    a = next(a for a in ARMS if a.name == name)
    return fkopt.mechanism(a.format, file=str(SUITES / a.file), base=a.base, tip=a.tip)


def frame_errors(m, q, T):
    """Position and geodesic rotation errors (from the trace, so a turn by pi counts) of FK rows."""
    F = m.fk_matrix(np.atleast_2d(q))
    dp = np.linalg.norm(F[:, :3, 3] - T[:3, 3], axis=1)
    M = F[:, :3, :3] @ T[:3, :3].T
    c = np.clip((np.trace(M, axis1=1, axis2=2) - 1) / 2, -1, 1)
    s = 0.5 * np.linalg.norm(np.stack([M[:, 2, 1] - M[:, 1, 2], M[:, 0, 2] - M[:, 2, 0], M[:, 1, 0] - M[:, 0, 1]],
                                      axis=1), axis=1)
    return dp, np.arctan2(s, c)


def nearest_zero_copy(m, q):
    """q with every revolute joint moved by whole turns to the in-limit value nearest 0."""
    out = q.copy()
    for i, (lo, hi) in enumerate(m.bounds):
        vals = [q[i] + 360.0 * k for k in range(-3, 4) if lo - 1e-9 <= q[i] + 360.0 * k <= hi + 1e-9]
        out[i] = min(vals, key=abs)
    return out


def turns_gap(rows, q):
    """Largest per-joint difference modulo 360 deg of each row from q."""
    return np.abs((rows - q + 180.0) % 360.0 - 180.0).max(axis=1)


@pytest.mark.parametrize("name", ["ur5", "ur5e-mj"])
def test_every_answer_is_verified_distinct_inside_the_limits_and_holds_the_generating_configuration(name):
    """URDF and MJCF arm: for FK of random in-limit configurations, every row reproduces the target
    to 1e-9 (checked here by the trace, independently of the solver), lies inside the limits, the
    rows differ modulo 360 deg, the generating configuration is one of them as its in-limit copy
    nearest 0, and a UR-type arm has at most 8."""
    m = stored(name)
    rng = np.random.default_rng(5)
    q = m.bounds[:, 0] + (m.bounds[:, 1] - m.bounds[:, 0]) * rng.random((6, m.dof))
    T = m.fk_matrix(q)
    for k in range(len(q)):
        r = fkopt.inverse(m, T[k], solutions="all")
        assert 1 <= len(r) <= 8 and r.solutions.shape == (len(r), m.dof)
        dp, dr = frame_errors(m, r.solutions, T[k])
        assert (dp <= 1e-9).all() and (dr <= 1e-9).all()
        assert (r.position_error <= 1e-9).all() and (r.rotation_error <= 1e-9).all()
        assert m.in_bounds(r.solutions).all()
        for i in range(len(r)):
            others = np.delete(r.solutions, i, axis=0)
            assert not len(others) or turns_gap(others, r.solutions[i]).min() > 1e-4
        gap = np.abs(r.solutions - nearest_zero_copy(m, q[k])).max(axis=1)
        assert gap.min() < 1e-6
        # the search ends by Pieper's bound (8 distinct before the limits) or by the patience rule
        assert (r.search["distinct"] == 8 and r.search["rule"].startswith("certificate")) or \
            (r.search["starts"] >= r.search["patience"] and "consecutive starts" in r.search["rule"])


def test_the_chain_geometry_gives_pieper_bound_and_two_solution_windows():
    """From the chain's axes alone: the UR5's joints 2-4 are parallel, the Kinova j2s6s200's
    last three meet in a point, the Panda with joint 7 locked has its first three meeting; the
    xArm 7 with joint 3 locked and the 5-joint SO-101 have no Pieper triple, hence no bound."""
    from fkopt.kinematics.branch_structure import structure
    from fkopt.kinematics.branches import _context
    ur = _context(stored("ur5"), {}, None)["structure"]
    assert ur["bound"] == 8 and ur["triple"] == (1, 2, 3, "parallel") and ur["pair_window"] == (1, 3)
    assert ur["windows"][0] == (1, 3) and ur["two_solution"][0]
    kin = _context(stored("kinova-j2s6s200"), {}, None)["structure"]
    assert kin["triple"] == (3, 4, 5, "concurrent") and kin["free_window"] == (0, 2)
    panda = stored("panda")
    assert _context(panda, {6: 0.3}, None)["structure"]["triple"] == (0, 1, 2, "concurrent")
    xarm = stored("xarm7")
    assert _context(xarm, {2: 0.3}, None)["structure"]["bound"] == 0
    assert _context(stored("so101"), {}, None)["structure"]["bound"] == 0
    # a masked pose has fewer equations: no bound
    assert _context(stored("ur5"), {}, np.array([1, 1, 1, 1, 1, 0.0]))["structure"]["bound"] == 0
    assert structure(panda.chain(), [], panda.reach)["bound"] == 0          # 7 unknowns


def test_the_certificate_is_never_claimed_short_and_an_odd_count_is_searched_on():
    """Pieper's bound as certificate: on UR5 and Kinova poses, the union of the sets found with
    four seeds never exceeds 8 distinct solutions, and whenever one run claims the certificate its
    set is that union; a run stopped by the patience rule on these chains has a count that is a
    multiple of 2 (UR5: parallel triple) or 4 (Kinova: concurrent wrist) unless it used up max_starts."""
    for name, multiple in (("ur5", 2), ("kinova-j2s6s200", 4)):
        m = stored(name)
        rng = np.random.default_rng(8)
        q = m.bounds[:, 0] + (m.bounds[:, 1] - m.bounds[:, 0]) * rng.random((8, m.dof))
        T = m.fk_matrix(q)
        claimed = 0
        for k in range(len(q)):
            runs = [fkopt.inverse(m, T[k], solutions="all", copies=True, seed=s) for s in range(4)]
            union = np.concatenate([r.solutions for r in runs])
            distinct = [row for i, row in enumerate(union) if i == 0 or turns_gap(union[:i], row).min() > 1e-4]
            assert len(distinct) <= 8 * 2 ** 5                         # copies: at most 8 solutions' turns
            for r in runs:
                if r.search["rule"].startswith("certificate"):
                    claimed += 1
                    assert r.search["distinct"] == 8
                    assert all(turns_gap(r.solutions, row).min() < 1e-6 for row in distinct)
                elif r.search["starts"] < r.search["max_starts"]:
                    assert r.search["distinct"] % multiple == 0
        assert claimed >= 8


def test_a_dh_arm_in_mm_with_one_joint_fixed_gives_its_generating_configuration():
    """A 7-joint DH arm (mm) with joint 3 locked at the generating value: every row keeps that
    value, is verified, and the generating configuration is among them."""
    m = fkopt.mechanism("7dof-arm")
    rng = np.random.default_rng(2)
    q = m.bounds[:, 0] + (m.bounds[:, 1] - m.bounds[:, 0]) * rng.random(m.dof)
    T = m.fk_matrix(q[None])[0]
    name = m.joint_names[2]
    r = fkopt.inverse(m, T, solutions="all", fixed={name: q[2]})
    assert len(r) >= 1 and r.fixed == {name: pytest.approx(q[2])}
    assert np.allclose(r.solutions[:, 2], q[2])
    dp, dr = frame_errors(m, r.solutions, T)
    assert (dp <= 1e-9 * 1000).all() and (dr <= 1e-9).all()            # mm: 1e-9 of the length unit
    assert np.abs(r.solutions - q).max(axis=1).min() < 1e-6


def test_a_redundant_arm_needs_fixed_or_spread_and_spread_samples_the_self_motion():
    """Without fixed joints a 7-joint arm's solutions are not finite: one line saying what to give.
    spread=K locks joint 3 at K values across its limits; every row is verified and carries its
    locked value, and several of the K values have solutions."""
    m = stored("iiwa-mj")
    q = m.bounds.mean(axis=1) + 7.0
    T = m.fk_matrix(q[None])[0]
    with pytest.raises(FkoptError, match=r"7 joints for 6 task components.*fixed=.*spread=K"):
        fkopt.inverse(m, T, solutions="all")
    r = fkopt.inverse(m, T, solutions="all", spread=6)
    locked = m.joint_names[2]
    assert set(r.fixed) == {locked} and len(r.fixed[locked]) == len(r)
    assert np.allclose(r.solutions[:, 2], r.fixed[locked])
    assert len(np.unique(np.round(r.fixed[locked], 6))) >= 2
    dp, dr = frame_errors(m, r.solutions, T)
    assert (dp <= 1e-9).all() and (dr <= 1e-9).all()
    with pytest.raises(FkoptError, match="fixed or spread, not both"):
        fkopt.inverse(m, T, solutions="all", spread=2, fixed={locked: 0.0})


def test_copies_lists_each_in_limit_turn_of_a_joint_with_limits_wider_than_a_turn():
    """UR5's joints other than the elbow span +-360 deg: with copies=True each solution comes with
    its in-limit copies (a joint at v also at v -+ 360), all verified; the default rows are among them."""
    m = stored("ur5")
    T = m.fk_matrix(np.array([[20.0, -70.0, 60.0, 30.0, 40.0, 50.0]]))[0]
    one = fkopt.inverse(m, T, solutions="all")
    every = fkopt.inverse(m, T, solutions="all", copies=True)
    assert len(every) > len(one)
    dp, dr = frame_errors(m, every.solutions, T)
    assert (dp <= 1e-9).all() and (dr <= 1e-9).all() and m.in_bounds(every.solutions).all()
    for row in one.solutions:
        assert np.abs(every.solutions - row).max(axis=1).min() < 1e-9
    # each row of every is a copy of one of one's rows
    assert all(turns_gap(one.solutions, row).min() < 1e-6 for row in every.solutions)


def test_a_turn_by_pi_about_the_tool_axis_is_not_a_solution():
    """The rotation vector of R Rt^T vanishes at exactly pi: a check on it alone would accept the
    UR5 with its last joint turned by 180 deg. The search's verification uses the trace too."""
    from fkopt.kinematics.branches import _context, _verify
    m = stored("ur5")
    q = np.array([10.0, -60.0, 80.0, 20.0, 50.0, 30.0])
    T = m.fk_matrix(q[None])[0]
    row = np.concatenate([T[:3, 3], T[:3, :3].ravel()])
    ctx = _context(m, {}, None)
    assert max(_verify(m, ctx, row, q, None)) < 1e-12
    pe, re = _verify(m, ctx, row, q + [0, 0, 0, 0, 0, 180.0], None)
    assert re == pytest.approx(np.pi)


def test_a_batch_gives_one_result_per_pose_and_bad_input_is_one_line():
    m = stored("ur5")
    T = m.fk_matrix(np.array([[20.0, -70.0, 60.0, 30.0, 40.0, 50.0], [0.0, -90.0, 90.0, 0.0, 90.0, 0.0]]))
    got = fkopt.inverse(m, T, solutions="all")
    assert isinstance(got, list) and len(got) == 2 and all(len(r) >= 1 for r in got)
    one = fkopt.inverse(m, T[1], solutions="all")
    assert np.array_equal(got[1].solutions, one.solutions)
    with pytest.raises(FkoptError, match="solutions: expected 'one' or 'all'"):
        fkopt.inverse(m, T[0], solutions="every")
    with pytest.raises(FkoptError, match="unknown joint 'q9'"):
        fkopt.inverse(m, T[0], solutions="all", fixed={"q9": 0.0})
    with pytest.raises(FkoptError, match=r"outside the joint's limits"):
        fkopt.inverse(m, T[0], solutions="all", fixed={"elbow_joint": 400.0})
    with pytest.raises(FkoptError, match="unreachable"):
        fkopt.inverse(m, [5.0, 0, 0, 0, 0, 0], solutions="all")
    with pytest.raises(FkoptError, match="patience: expected an integer"):
        fkopt.inverse(m, T[0], solutions="all", patience=0)


def test_cli_all_solutions_prints_every_verified_solution_and_refuses_fixed_without_it(cli, tmp_path):
    geo = tmp_path / "ur5.yaml"
    geo.write_text(f"file: {SUITES / 'robots' / 'ur5.urdf'}\nbase: base_link\ntip: tool0\n")
    pose = "x=0.4,y=0.2,z=0.3,alpha=10,beta=120,gamma=30"
    code, out, err = cli("ik", "urdf", "--geometry", geo, "--pose", pose, "--all-solutions", "--json")
    assert code == 0, err
    data = json.loads(out)
    m = fkopt.mechanism("urdf", file=str(SUITES / "robots" / "ur5.urdf"), base="base_link", tip="tool0")
    rows = np.array([[s[n] for n in m.joint_names] for s in data["solutions"]])
    assert data["count"] == len(rows) >= 2
    target = m.fk(rows)                                  # every row reaches the same pose
    assert np.abs(target - np.array([0.4, 0.2, 0.3, 10, 120, 30])).max() < 1e-6
    code, out, err = cli("ik", "urdf", "--geometry", geo, "--pose", pose, "--fixed", "elbow_joint=1")
    assert code == 2 and "--fixed: only with --all-solutions" in err and "Traceback" not in err


def test_all_solutions_recall_against_eaik_on_the_ur5():
    """External: EAIK's analytic in-limit solutions of 100 poses of the UR5 (its adapter,
    fkopt/adapters/field/eaik.py): fkopt returns at least 99 % of them and no row that fails
    verification at 1e-9 m / 1e-9 rad (docs/robots.md has the 1000-pose measurement per arm)."""
    pytest.importorskip("eaik")
    from fkopt.adapters.field.eaik import EAIK
    m = stored("ur5")
    ref = EAIK(m, timeout=1.0, rng=np.random.default_rng(0))
    rng = np.random.default_rng(11)
    q = m.bounds[:, 0] + (m.bounds[:, 1] - m.bounds[:, 0]) * rng.random((100, m.dof))
    T = m.fk_matrix(q)
    total = missed = failed = 0
    for k in range(len(q)):
        r = fkopt.inverse(m, T[k], solutions="all")
        dp, dr = frame_errors(m, r.solutions, T[k])
        failed += int(((dp > 1e-9) | (dr > 1e-9)).sum())
        s = ref.solutions(T[k])
        for row in s.joints[~s.least_squares & s.in_limits]:
            total += 1
            missed += int(not len(r) or turns_gap(r.solutions, row).min() > 1e-4)
    assert failed == 0 and total > 500 and missed <= 0.01 * total


def test_without_the_compiled_path_it_refuses_with_one_line(monkeypatch):
    m = stored("ur5")
    T = m.fk_matrix(np.array([[20.0, -70.0, 60.0, 30.0, 40.0, 50.0]]))[0]
    monkeypatch.setenv("FKOPT_NUMERICS", "numpy")
    with pytest.raises(FkoptError, match="need numba"):
        fkopt.inverse(m, T, solutions="all")
    with pytest.raises(FkoptError, match="need numba"):
        fkopt.inverse_path(m, T[None], start=[20.0, -70.0, 60.0, 30.0, 40.0, 50.0])


def test_the_reversed_chain_gives_the_inverse_frame():
    """branch_structure.reversed_chain: FK of the chain walked from the tool at the reversed joints
    is the inverse of the tool frame, on a URDF arm with a locked joint and on a DH arm with offsets."""
    from fkopt.kinematics.branch_structure import reversed_chain
    from fkopt.kinematics.branches import _reduced_chain
    from fkopt.numerics.chain import frame_jacobian1
    rng = np.random.default_rng(3)
    for chain in (_reduced_chain(stored("panda").chain(), {6: 0.3}), fkopt.mechanism("7dof-arm").chain()):
        back = reversed_chain(chain)
        for _ in range(5):
            t = rng.uniform(-3, 3, chain.dof)
            p, R, _ = frame_jacobian1(chain, t.tolist())
            pb, Rb, _ = frame_jacobian1(back, t[::-1].tolist())
            R = np.array(R)
            assert np.abs(np.array(Rb) - R.T).max() < 1e-12
            assert np.abs(np.array(pb) + R.T @ np.array(p)).max() < 1e-9 * max(1.0, np.abs(p).max())


def test_the_panda_with_joint_7_locked_gives_every_generating_configuration():
    """The 6R chain left of the Panda (its Pieper triple at the base, searched from the tool): for
    FK of 20 in-limit configurations, among them near-singular ones whose loop converges slowly,
    the generating configuration is always among the verified rows."""
    m = stored("panda")
    rng = np.random.default_rng(2026)
    q = m.bounds[:, 0] + (m.bounds[:, 1] - m.bounds[:, 0]) * rng.random((20, m.dof))
    v = float(m.bounds[6, 0] + 0.3 * (m.bounds[6, 1] - m.bounds[6, 0]))
    q[:, 6] = v
    T = m.fk_matrix(q)
    for k in range(len(q)):
        r = fkopt.inverse(m, T[k], solutions="all", fixed={"panda_joint7": v})
        dp, dr = frame_errors(m, r.solutions, T[k])
        assert (dp <= 1e-9).all() and (dr <= 1e-9).all()
        assert turns_gap(r.solutions, q[k]).min() < 1e-6, k
