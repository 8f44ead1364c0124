"""The verdict machinery: rank tests, equal-evaluation reads of trace.csv.gz, timing verdicts, the
selection parameter behind mao2017's Tab. 3 floor, and `fkopt check` failing on a changed verdict."""
import shutil
from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.algorithms.abc import quality
from fkopt.problems import fk_problem
from fkopt.registry import mechanism_class
from fkopt.reproduce.check import check_experiment
from fkopt.reproduce.claims import (HELD, NOT_HELD, WITHIN_NOISE, at_evaluations, at_iteration, compare,
                                    faster_claim, first_below, verdict_changes)
from fkopt.reproduce.report import claims_files
from fkopt.reproduce.store import Experiment, Store
from fkopt.solve import solve

ROOT = Path(__file__).resolve().parents[1]


def test_identical_samples_are_no_difference():
    c = compare("A", [1.0, 2.0, 3.0], "B", [3.0, 1.0, 2.0])
    assert c.p == 1.0 and c.lower is None
    c = compare("A", [0.0] * 30, "B", [0.0] * 30)     # every run exact: no difference either
    assert c.p == 1.0 and c.lower is None


def test_rank_test_finds_the_lower_sample_and_ignores_overlap():
    rng = np.random.default_rng(0)
    a, b = rng.normal(0, 1, 30), rng.normal(3, 1, 30)
    assert compare("A", a, "B", b).lower == "A"
    assert compare("B", b, "A", a).lower == "A"
    assert compare("A", a, "B", a + 0.01).lower is None   # a shift far inside the spread
    c = compare("A", a, "B", b)
    assert c.p < 1e-6 and "p < 1e-4" in c.text()


def _fake_experiment(tmp_path) -> Experiment:
    folder = tmp_path / "paper" / "exp"
    folder.mkdir(parents=True)
    (folder / "meta.json").write_text('{"config": {}}')
    # run 0 of "a": f = 8 at 0 evaluations, 4 at 100, 1 at 300; run 1 stops at iteration 2
    pd.DataFrame({"case": "c", "algorithm": "a", "run": [0, 0, 0, 1, 1],
                  "iteration": [0, 1, 3, 0, 2], "evaluations": [10, 100, 300, 10, 200],
                  "best_fitness": [8.0, 4.0, 1.0, 9.0, 0.5]}).to_csv(folder / "trace.csv.gz", index=False)
    pd.DataFrame({"case": "c", "algorithm": "a", "run": [0, 1], "final_fitness": [1.0, 0.5],
                  "evaluations": [400, 200], "iterations_done": [4, 2]}).to_csv(folder / "runs.csv", index=False)
    return Experiment(folder)


def test_best_so_far_at_equal_evaluations_and_iterations(tmp_path):
    exp = _fake_experiment(tmp_path)
    np.testing.assert_array_equal(at_evaluations(exp, "a", 99), [8.0, 9.0])
    np.testing.assert_array_equal(at_evaluations(exp, "a", 250), [4.0, 0.5])
    np.testing.assert_array_equal(at_evaluations(exp, "a", 1e9), [1.0, 0.5])   # a stopped run keeps its value
    np.testing.assert_array_equal(at_iteration(exp, "a", 2), [4.0, 0.5])
    np.testing.assert_array_equal(at_iteration(exp, "a"), [1.0, 0.5])           # the end: runs.csv
    it, ev = first_below(exp, "a", 2.0)
    np.testing.assert_array_equal(it, [3, 2])
    np.testing.assert_array_equal(ev, [300, 200])


def test_timing_verdicts_follow_the_spread():
    fast, slow = np.linspace(10, 12, 10), np.linspace(20, 24, 10)
    assert faster_claim("x", "A", compare("A", fast, "B", slow)).verdict == HELD
    assert faster_claim("x", "B", compare("A", fast, "B", slow)).verdict == NOT_HELD
    noisy = faster_claim("x", "A", compare("A", fast, "B", fast[::-1] + 0.05))
    assert noisy.verdict == WITHIN_NOISE and noisy.numbers["p"] >= 0.05


def test_karaboga_selection_stops_at_the_quality_floor():
    # 1/(1+f) == 1 below ~1.1e-16: the floor that mao2017's Tab. 3 prints
    assert quality(np.array([1e-16]))[0] == 1.0 and quality(np.array([1e-15]))[0] < 1.0
    mech = mechanism_class("3-rps")()
    pr = fk_problem(mech, mech.ik(np.array([9.0, 13.0, 622.0])))
    kw = dict(population=10, iterations=600, runs=8, seed=2017)
    raw = solve(pr, "abc", **kw)
    kara = solve(pr, "abc", params={"selection": "karaboga"}, **kw)
    assert np.all(raw.fitness == 0.0)
    assert np.all((kara.fitness > 0) & (kara.fitness < 1.2e-16))
    assert 1e-17 < kara.fitness.mean() < 1.1e-16
    default = solve(pr, "abc", params={"selection": "raw"}, **kw)
    np.testing.assert_array_equal(default.history, raw.history)   # the default is raw f


def test_verdict_changes_are_detected(tmp_path):
    src = ROOT / "results" / "liu2008"
    root = tmp_path / "results"
    shutil.copytree(src, root / "liu2008")
    for path, df in claims_files(root).items():
        df.to_csv(path, index=False)
    assert verdict_changes(root) == []
    file = root / "liu2008" / "claims.csv"
    df = pd.read_csv(file)
    df.loc[0, "verdict"] = HELD if df.loc[0, "verdict"] != HELD else NOT_HELD
    df.to_csv(file, index=False)
    changes = verdict_changes(root)
    assert len(changes) == 1 and changes[0][1] == df.loc[0, "claim"]


def test_check_fails_when_a_verdict_changes(tmp_path):
    root = tmp_path / "results"
    shutil.copytree(ROOT / "results" / "mao2017", root / "mao2017")
    for path, df in claims_files(root).items():
        df.to_csv(path, index=False)
    file = root / "mao2017" / "claims.csv"
    df = pd.read_csv(file)
    row = df.index[df.claim.str.startswith("Fig. 3: stopping")][0]
    df.loc[row, "verdict"] = HELD if df.loc[row, "verdict"] != HELD else NOT_HELD
    df.to_csv(file, index=False)
    bad = check_experiment(Store(root).get("mao2017", "tab4_tab5_fig3"))
    verdicts = [m for m in bad if m.column == "verdict"]
    assert len(verdicts) == 1 and verdicts[0].file == "claims.csv"
    assert "stored" in str(verdicts[0]) and "Fig. 3: stopping" in str(verdicts[0])
