"""Fast tests of modules otherwise reached only by slow tiers: the assembly report's claims and
the reproduce agreement line."""
from types import SimpleNamespace

import numpy as np

import fkopt
from fkopt.reproduce import assembly as assembly_report
from fkopt.reproduce.claims import HELD, NOT_CHECKABLE, NOT_HELD


class Store:
    def __init__(self, found, method="homotopy"):
        self.found, self.method = found, method

    def get(self, paper, name):
        if self.found is None:
            return None
        row = SimpleNamespace(solutions_found=self.found, starts=600, worst_fitness=1e-14, total_s=0.5,
                              method=self.method)
        return SimpleNamespace(row=lambda *a, **k: row)


def test_assembly_claim_holds_only_at_40_solutions_and_is_not_checkable_without_a_result():
    assert assembly_report.claims(Store(40))[0].verdict == HELD
    assert assembly_report.claims(Store(39))[0].verdict == NOT_HELD
    assert assembly_report.claims(Store(None))[0].verdict == NOT_CHECKABLE
    assert assembly_report.timing_claims(Store(None)) == []
    # the condition says what the count came from: the certified homotopy's paths or the restarts' starts
    assert "600 homotopy paths" in assembly_report.claims(Store(40))[0].evidence
    assert "600 starts" in assembly_report.claims(Store(40, "restarts"))[0].evidence


def test_reproduce_agreement_line_counts_moved_files_and_judges_them_by_the_cross_platform_rules(tmp_path):
    """The line `fkopt reproduce` ends with (issue 32): nothing moved; a last-digit move that
    fkopt check's cross-platform rules accept; a moved number they refuse."""
    import shutil
    from pathlib import Path

    from fkopt.reproduce.changes import agreement, snapshot
    root = tmp_path / "results"
    shutil.copytree(Path(__file__).resolve().parents[1] / "results" / "liu2008" / "tab3_fig4",
                    root / "liu2008" / "tab3_fig4")
    runs = root / "liu2008" / "tab3_fig4" / "runs.csv"
    text = runs.read_text()

    def line_after(edit):
        keep = tmp_path / f"keep{len(list(tmp_path.iterdir()))}"
        keep.mkdir()
        runs.write_text(text)
        before = snapshot(root, keep=keep)
        runs.write_text(edit(text))
        return agreement(before, root)

    assert "byte-identical" in line_after(lambda t: t)
    ulp = line_after(lambda t: t.replace("9.408561477e-08", "9.408561478e-08", 1))
    assert ulp.startswith("reproduce: 1 deterministic files in 1 results moved") and "accept all" in ulp
    big = line_after(lambda t: "".join(t.splitlines(keepends=True)[:-3]))        # runs lost
    assert "refuse" in big and "liu2008/tab3_fig4 runs.csv" in big


def test_reproduce_hashes_the_regenerated_tree_once_for_changes_and_its_agreement_line(tmp_path, monkeypatch):
    """write_report's CHANGES.md and `fkopt reproduce`'s last line are judged on one snapshot of
    the tree after the rerun (issue 32): one pass over its files, and the same line as from a
    fresh snapshot."""
    import shutil
    from pathlib import Path

    from fkopt.reproduce import changes
    from fkopt.reproduce.report import write_report
    root = tmp_path / "results"
    shutil.copytree(Path(__file__).resolve().parents[1] / "results" / "liu2008" / "tab3_fig4",
                    root / "liu2008" / "tab3_fig4")
    runs = root / "liu2008" / "tab3_fig4" / "runs.csv"
    (tmp_path / "keep").mkdir()
    before = changes.snapshot(root, keep=tmp_path / "keep")
    runs.write_text(runs.read_text().replace("9.408561477e-08", "9.408561478e-08", 1))
    taken = []
    real = changes.snapshot
    monkeypatch.setattr(changes, "snapshot", lambda *a, **k: taken.append(a) or real(*a, **k))
    written = write_report(root, changes_since=before)
    line = changes.agreement(before, root, written.after)
    assert len(taken) == 1 and written.after is not None and root / "CHANGES.md" in written.paths
    assert line == changes.agreement(before, root) and "1 deterministic files in 1 results moved" in line
    assert "runs.csv" in (root / "CHANGES.md").read_text()


def test_field_solvers_answer_on_the_stored_ur5_and_kinbench_judges_them():
    """The outside IK wrappers (TRAC-IK, rtb ik_LM/ik_NR) on the suite's stored UR5: every answer
    judged by kinbench's own FK (the fast tier's reach; tests/test_field.py checks against pinocchio)."""
    import numpy as np
    import pytest

    import fkopt
    from fkopt.adapters.field import solve
    from fkopt.registry import clock_solver as make_ik
    from fkopt.kinbench.physical import ik_verdicts
    arm = fkopt.mechanism("urdf", file="configs/suites/robots/ur5.urdf", base="base_link", tip="tool0")
    rng = np.random.default_rng(4)
    q = arm.bounds[:, 0] + rng.random((3, arm.dof)) * (arm.bounds[:, 1] - arm.bounds[:, 0])
    T = arm.fk_matrix(q)
    for name in ("tracik", "rtb-ik_LM", "rtb-ik_NR"):
        try:
            solver = make_ik(name, arm, timeout=0.05, rng=np.random.default_rng(0))
        except fkopt.FkoptError as err:       # the field extra is not installed
            pytest.skip(str(err))
        answers = solve(solver, T)
        v = ik_verdicts(arm, answers.joints, T)
        assert answers.joints.shape == (3, arm.dof) and (answers.seconds > 0).all()
        assert v["success"][:, 0].sum() >= 2, (name, v)          # 5 mm / 0.05 rad on most of 3 poses


def test_by_algorithm_judges_a_swarm_answer_like_the_exact_solvers():
    import numpy as np

    import fkopt
    from fkopt.kinematics.by_algorithm import forward_by, inverse_by
    m = fkopt.mechanism("3-rps")
    legs = m.ik(np.array([9.0, 13.0, 622.0]))
    r = forward_by(m, legs, "gabc+lm", tol=1e-6, budget={"population": 10, "iterations": 60})
    assert bool(r.solved) == bool(np.abs(m.ik(r.pose) - legs).max() <= 1e-6 and m.in_bounds(r.pose))
    arm = fkopt.mechanism("7dof-arm")
    pose = arm.fk(np.array([45.0, 0, 45, 0, 45, 0, 0]))
    s = inverse_by(arm, pose, "pso", budget={"population": 10, "iterations": 20})
    assert not bool(s.solved) and float(s.position_error) > 1e-6 and s.as_dict()["joints"].keys() == set(arm.joint_names)
