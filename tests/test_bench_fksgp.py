"""`fkopt bench --section fksgp` (issue 38): fkopt's all_solutions beside the vendored fkSGP
snapshot on random general 6-6 platforms, or a one-line skip without it."""
import numpy as np
import pytest

from fkopt.numerics import path as numerics_path
from fkopt.tools.bench import fksgp
from fkopt.tools.bench.measuring import Rows


def test_without_the_vendored_snapshot_the_section_says_so_and_adds_no_row(monkeypatch):
    monkeypatch.setattr(fksgp, "fksgp_folder", lambda: None)
    rows, msgs = Rows(), []
    fksgp.bench_fksgp(rows, True, msgs)
    assert rows.rows == [] and len(msgs) == 1 and "no vendored fkSGP snapshot" in msgs[0]


def test_beside_fksgp_every_platform_gives_the_same_real_solutions(monkeypatch):
    if fksgp.fksgp_folder() is None:
        pytest.skip("no vendored fkSGP snapshot (../shared/vendor/fksgp or FKSGP_PATH)")
    monkeypatch.setattr(fksgp, "QUICK_PLATFORMS", 2)
    rows, msgs = Rows(), []
    fksgp.bench_fksgp(rows, True, msgs)
    got = {r["item"]: r for r in rows.rows}
    ratio = got["6-6 all real solutions / fkSGP"]
    assert np.isfinite(ratio["value"]) and ratio["value"] > 0 and "load average" in ratio["note"]
    assert got["platforms with the same real solution set"]["value"] == 2, got
    assert got["6-6 all real solutions / fkSGP, CPU time"]["value"] > 0
    if numerics_path.compiled() is not None:          # the certified homotopy ran on both platforms
        assert "2 homotopy" in ratio["note"], ratio["note"]
    assert not msgs


def test_rigid_motions_match_within_the_tolerance_only():
    R = np.eye(3)
    t = np.array([0.5, -1.0, 2.0])
    assert fksgp._same_sets([(R, t)], [(R, t + 1e-9)], [True]) == (1, 0, 0)
    assert fksgp._same_sets([(R, t)], [(R, t + 1e-3)], [True]) == (0, 1, 1)
    assert fksgp._same_sets([], [(R, t)], [False]) == (0, 0, 0)     # outside fkopt's bounds: not missing
