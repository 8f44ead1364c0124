"""Fast tests of modules otherwise reached only by slow tiers: the assembly report's claims and
the robots bench's answer check."""
from types import SimpleNamespace

import numpy as np

import fkopt
from fkopt.bench_robots import _check
from fkopt.reproduce import assembly as assembly_report
from fkopt.reproduce.claims import HELD, NOT_CHECKABLE, NOT_HELD


class Store:
    def __init__(self, found):
        self.found = found

    def get(self, paper, name):
        if self.found is None:
            return None
        row = SimpleNamespace(solutions_found=self.found, starts=600, worst_fitness=1e-14, total_s=0.5)
        return SimpleNamespace(row=lambda *a, **k: row)


def test_assembly_claim_holds_only_at_40_solutions_and_is_not_checkable_without_a_result():
    assert assembly_report.claims(Store(40))[0].verdict == HELD
    assert assembly_report.claims(Store(39))[0].verdict == NOT_HELD
    assert assembly_report.claims(Store(None))[0].verdict == NOT_CHECKABLE
    assert assembly_report.timing_claims(Store(None)) == []


def test_robots_bench_check_accepts_the_arms_own_pose_and_refuses_a_moved_or_out_of_limit_one():
    m = fkopt.mechanism("7dof-arm")
    rng = np.random.default_rng(0)
    q = m.bounds[:, 0] + rng.random((4, m.dof)) * (m.bounds[:, 1] - m.bounds[:, 0])
    T = m.fk_matrix(q)
    assert _check(m, q, T, (1e-6, 1e-6), 1.0).all()      # the bench's tolerance; arccos near 1 is ~1e-8 rad coarse
    moved = T.copy()
    moved[:, 0, 3] += 1.0                                 # one length unit away
    assert not _check(m, q, moved, (1e-3, 1e-3), 1.0).any()
    outside = q.copy()
    outside[:, 0] = m.bounds[0, 1] + 1.0
    assert not _check(m, outside, m.fk_matrix(outside), (1e-6, 1e-6), 1.0).any()


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
