"""bench: quick run writes bench.csv/scaling.png with every section and sane values (no timing asserts)."""
import numpy as np
import pandas as pd

import fkopt
from fkopt.tools.bench import c_reference, sections as bench, swarms
from fkopt.tools.bench.measuring import Rows
def test_quick_run_writes_csv_and_plot(tmp_path):
    df = bench.run(quick=True, peers=False, out=tmp_path / "b")
    csv = pd.read_csv(tmp_path / "b" / "bench.csv")
    assert list(csv.columns) == ["section", "item", "value", "unit", "note"]
    import matplotlib.image as mpimg
    img = mpimg.imread(tmp_path / "b" / "scaling.png")   # a decodable PNG with a drawn plot, not blank
    assert img.ndim == 3 and img.shape[0] > 100 and img.shape[1] > 100
    assert len(np.unique(img.reshape(-1, img.shape[-1]), axis=0)) > 10
    assert len(csv) == len(df)
    core = {"throughput", "mao2017", "exact", "kinematics", "cases", "scaling"}
    assert core <= set(csv.section) <= core | {"ik-one-pose", "ik-batch", "swarms", "fksgp"}   # when rtb, pinocchio, a C compiler, fkSGP are there
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
    for n in (1, 10, 100):   # N cases x 30 runs together
        assert v[f"gabc {n} cases x 30 runs per evaluation"] > 0
    # the IK sections (when rtb and pinocchio are there): every arm's answers verified by an FK not
    # fkopt's; fkopt never reports solved what the check refuses
    batch = csv[(csv.section == "ik-batch") & (csv.unit == "x rtb")]
    for note in batch.note[~batch.item.isin(["median over arms", "largest"])]:
        assert note.endswith("fkopt reported solved but not: 0"), note
    if len(batch):
        assert "rtb DHRobot FK" in batch.note[batch.item == "wang7dof"].iloc[0]
    # the swarms section (with a C compiler and numba): every compiled run equals the numpy path's,
    # and ABC and GABC say that they ran many iterations per compiled call
    fast = csv[(csv.section == "swarms") & csv.note.str.startswith("default path")]
    for item, note in zip(fast.item, fast.note):
        assert "runs bit-identical to FKOPT_NUMERICS=numpy" in note, item
        assert ("many iterations per call" in note) == (not item.startswith("pso")), item


def test_batched_lm_solves_many_poses_as_cases():
    m = fkopt.mechanism("6-sps-cmm")
    rng = np.random.default_rng(3)
    poses = m.bounds[:, 0] + rng.random((5, 6)) * (m.bounds[:, 1] - m.bounds[:, 0])
    p = fkopt.fk_problem(m, m.ik(poses))
    np.testing.assert_allclose(p.fitness(poses[:, None, :])[:, 0], 0.0, atol=1e-20)
    r = fkopt.solve(p, "lm", population=1, iterations=50, runs=1, x0=m.bounds.mean(axis=1))
    assert r.x.shape == (5, 1, 6)
    assert np.abs(m.ik(r.x[:, 0]) - m.ik(poses)).max() < 1e-9


def test_sections_select_what_runs(tmp_path):
    df = bench.run(quick=True, out=tmp_path / "e", sections=["exact"])
    assert set(df.section) == {"exact"}
    assert not (tmp_path / "e" / "scaling.png").exists()


def test_bench_cli_refuses_unknown_section(tmp_path, fkopt_run):
    p = fkopt_run("bench", "--section", "nope", "--out", str(tmp_path / "x"))
    assert p.returncode == 2 and "kinematics" in p.stderr and "Traceback" not in p.stderr
    assert not (tmp_path / "x").exists()


def test_compiled_reference_solves_the_same_problem(tmp_path):
    """The C loop the cases section times is GABC on the 3-RPS fitness: same budget in
    evaluations, and it solves the poses as fkopt does (a broken loop would not)."""
    import shutil
    import pytest
    built = c_reference.compile_reference(tmp_path)
    if isinstance(built, str):
        assert shutil.which("gcc") is None and shutil.which("cc") is None and shutil.which("clang") is None, built
        pytest.skip(built)
    m = fkopt.mechanism("3-rps")
    poses = m.bounds[:, 0] + np.random.default_rng(3).random((4, 3)) * (m.bounds[:, 1] - m.bounds[:, 0])
    out = c_reference.run_reference(built[0], m.ik(poses), 200, 10, 5)
    r = fkopt.solve(fkopt.fk_problem(m, m.ik(poses)), "gabc", population=10, iterations=200, runs=5, seed=1)
    per_run = out["evaluations"] / 20
    assert 2 * 10 * 200 + 10 <= per_run <= 2 * 10 * 200 + 10 + 200        # + at most one scout per iteration
    assert abs(per_run - r.evaluations.mean()) < 50
    assert out["median"] < 1e-12 and np.median(r.fitness) < 1e-12
    assert out["seconds"] > 0


def test_compiled_reference_abc_and_pso_loops_solve_the_same_problem(tmp_path):
    """The swarms section's C loops of ABC and PSO: fkopt's budget in evaluations (PSO exactly
    population per iteration), and they solve the poses as fkopt does (a broken loop would not)."""
    import pytest
    built = c_reference.compile_reference(tmp_path)
    if isinstance(built, str):
        pytest.skip(built)
    m = fkopt.mechanism("3-rps")
    poses = m.bounds[:, 0] + np.random.default_rng(4).random((4, 3)) * (m.bounds[:, 1] - m.bounds[:, 0])
    joints = m.ik(poses)
    for alg, iterations in (("abc", 300), ("pso", 300)):
        out = c_reference.run_reference(built[0], joints, iterations, 10, 5, algorithm=alg)
        r = fkopt.solve(fkopt.fk_problem(m, joints), alg, population=10, iterations=iterations, runs=5, seed=1)
        per_run = out["evaluations"] / 20
        assert abs(per_run - r.evaluations.mean()) < 50, alg
        if alg == "pso":
            assert per_run == 10 * (iterations + 1)
        assert out["median"] < 1e-6 and np.median(r.fitness) < 1e-6, (alg, out["median"], np.median(r.fitness))


def test_swarms_pygmo_row_compares_bee_colony_with_the_batched_abc():
    """The swarms section's pygmo row (quick): pygmo's bee_colony on the numba-compiled 3-RPS
    fitness beside fkopt's batched ABC, both paths, ratio per run with the target verdict; both
    solve mao2017's case (no timing asserted)."""
    import pytest
    pytest.importorskip("pygmo")
    pytest.importorskip("numba")
    rows = Rows()
    messages = []
    swarms.bench_pygmo_abc(rows, True, messages)
    df = pd.DataFrame(rows.rows)
    got = df[df.item.str.startswith("pygmo bee_colony")]
    assert len(got) == 2 and not messages
    assert np.all(np.isfinite(got.value)) and np.all(got.value > 0)
    for note in got.note:
        assert "target >= 10:" in note and "2010 evaluations" in note    # gen 100: 10 + 100 * 20
