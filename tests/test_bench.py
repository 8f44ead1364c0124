"""bench: quick run writes bench.csv/scaling.png with every section and sane values (no timing asserts)."""
import numpy as np
import pandas as pd

import fkopt
from fkopt import bench


def test_quick_run_writes_csv_and_plot(tmp_path):
    df = bench.run(quick=True, peers=False, out=tmp_path / "b")
    csv = pd.read_csv(tmp_path / "b" / "bench.csv")
    assert list(csv.columns) == ["section", "item", "value", "unit", "note"]
    assert (tmp_path / "b" / "scaling.png").stat().st_size > 0
    assert len(csv) == len(df)
    assert set(csv.section) == {"throughput", "mao2017", "exact", "kinematics", "scaling"}
    assert np.all(np.isfinite(csv.value)) and np.all(csv.value >= 0)
    # every registered mechanism has a throughput row
    for name in fkopt.MECHANISMS:
        assert f"{name} batch 1e4" in set(csv.item)
    v = dict(zip(csv.item, csv.value))
    # mao2017 Tab. 3 budget: ABC/GABC use 2 evaluations per source and iteration (+ scouts)
    assert v["abc evaluations per run"] >= 2 * 10 * 600
    assert v["gabc evaluations per run"] >= 2 * 10 * 600
    # the batched exact solve finds legs to 1e-9 for (nearly) every pose
    assert v["6-sps-cmm lm success"] >= 99.0


def test_pose_batch_problem_index_is_inert():
    m = fkopt.mechanism("6-sps-cmm")
    rng = np.random.default_rng(3)
    poses = m.bounds[:, 0] + rng.random((5, 6)) * (m.bounds[:, 1] - m.bounds[:, 0])
    p = bench.PoseBatchProblem(m, m.ik(poses))
    x = np.concatenate([poses, np.arange(5.0)[:, None]], axis=1)
    np.testing.assert_allclose(p.fitness(x), 0.0, atol=1e-20)
    # flat, nested and shifted-index shapes select the right pose
    assert p.residuals(x[None, :, None, :]).shape == (1, 5, 1, 6)
    x2 = x.copy()
    x2[:, -1] += 1e-3
    np.testing.assert_array_equal(p.residuals(x2), p.residuals(x))
    r = fkopt.solve(p, "lm", population=1, iterations=50, runs=5, x0=p.start())
    np.testing.assert_array_equal(r.x[:, -1], np.arange(5.0))
    assert np.abs(m.ik(r.x[:, :-1]) - m.ik(poses)).max() < 1e-9


def test_sections_select_what_runs(tmp_path):
    df = bench.run(quick=True, out=tmp_path / "e", sections=["exact"])
    assert set(df.section) == {"exact"}
    assert not (tmp_path / "e" / "scaling.png").exists()


def test_bench_cli_refuses_unknown_section(tmp_path):
    import subprocess
    import sys
    p = subprocess.run([sys.executable, "-m", "fkopt.cli", "bench", "--section", "nope", "--out", str(tmp_path / "x")],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and "kinematics" in p.stderr and "Traceback" not in p.stderr
    assert not (tmp_path / "x").exists()
