"""The verdict machinery: rank tests, equal-evaluation reads of trace.csv.gz, timing verdicts, the
selection parameter behind mao2017's Tab. 3 floor, and `fkopt check` failing on a changed verdict."""
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fkopt.algorithms.abc import quality
from fkopt.problems import fk_problem
from fkopt.registry import mechanism_class
from fkopt.reproduce.check import check_experiment
from fkopt.reproduce.claims import (HELD, NOT_CHECKABLE, NOT_HELD, WITHIN_NOISE, at_evaluations, at_iteration,
                                    compare, faster_claim, first_below)
from fkopt.reproduce.drift import verdict_changes
from fkopt.reproduce.engine import is_claims_file, judge
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


def test_equal_evaluations_read_what_the_algorithm_returns(tmp_path):
    """Not the lowest fitness ever evaluated: a Karaboga ABC cannot tell f under ~1.1e-16 apart and
    keeps the first such source, so that is what it returns; a finished run returns its final answer."""
    from fkopt.reproduce.claims import accepted_trace
    f = np.array([1.0, 1e-3, 1e-17, 5e-18, 1e-19])
    np.testing.assert_array_equal(accepted_trace(f, "raw"), f)
    np.testing.assert_array_equal(accepted_trace(f, "karaboga"), [1.0, 1e-3, 1e-17, 1e-17, 1e-17])
    exp = _fake_experiment(tmp_path)
    runs = pd.read_csv(exp.folder / "runs.csv")
    runs.loc[1, "final_fitness"] = 0.7   # the returned answer, not the trace's lowest 0.5
    runs.to_csv(exp.folder / "runs.csv", index=False)
    np.testing.assert_array_equal(at_evaluations(exp, "a", 250), [4.0, 0.7])   # run 1 (200 evaluations) is done


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
    assert verdict_changes(root, timing=True) == []   # timing verdicts are stored and compared apart
    assert len(changes) == 1 and changes[0][1] == f'{df.loc[0, "id"]}: {df.loc[0, "claim"]}'


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
    # caught twice: the stored file is not what the engine writes from the stored runs (verdict_files),
    # and the rerun's verdict differs from the stored one (rerun_verdict_drift)
    assert len(verdicts) == 2 and {m.file for m in verdicts} == {"claims.csv"}
    assert {m.rule for m in verdicts} == {"same verdict", verdicts[0].rule} and "older engine" not in str(verdicts)
    assert all(str(m.row).startswith("fig3-gabc-fewer-iterations") for m in verdicts)
    assert any("Fig. 3: stopping" in str(m) for m in verdicts)


def _two_algorithms(tmp_path) -> Store:
    """30 runs each of "a" (10 evaluations per iteration) and "b" (20): at the end of 10 iterations b
    is lower, but at a's 100 evaluations (b's iteration 5) a is lower."""
    folder = tmp_path / "paper" / "exp"
    folder.mkdir(parents=True)
    (folder / "meta.json").write_text('{"config": {"iterations": 10}}')
    rng = np.random.default_rng(1)
    trace, runs = [], []
    for algo, cost, slope in (("a", 10, 1.0), ("b", 20, 1.5)):
        for r in range(30):
            noise = rng.uniform(0.9, 1.1)
            for it in range(11):
                trace.append({"case": "c", "algorithm": algo, "run": r, "iteration": it, "evaluations": cost * it,
                              "best_fitness": noise * 10.0 ** (-slope * it)})
            runs.append({"case": "c", "algorithm": algo, "run": r, "final_fitness": noise * 10.0 ** (-slope * 10),
                         "evaluations": cost * 10, "iterations_to_threshold": np.nan, "evaluations_to_threshold": np.nan})
    pd.DataFrame(trace).to_csv(folder / "trace.csv.gz", index=False)
    pd.DataFrame(runs).to_csv(folder / "runs.csv", index=False)
    pd.DataFrame({"case": "c", "algorithm": ["a", "b"], "iteration": 10, "mean_evaluations": [100, 200]}).to_csv(
        folder / "convergence.csv", index=False)
    return Store(tmp_path)


def test_a_comparison_reports_both_budget_bases_and_flags_their_disagreement(tmp_path):
    store = _two_algorithms(tmp_path)
    spec = {"id": "x", "text": "b beats a", "kind": "comparison", "experiment": "exp", "better": "b", "than": "a",
            "basis": "iterations"}
    c, = judge("paper", spec, store)
    assert c.verdict == HELD and c.numbers["lower_a"] == "b" and c.numbers["lower_evaluations_a"] == "a"
    assert c.numbers["bases_disagree"] and "bases disagree" in c.evidence
    c, = judge("paper", {**spec, "basis": "evaluations"}, store)
    assert c.verdict == NOT_HELD          # the same numbers on the other basis


def test_readings_give_one_conditional_row_each_and_not_checkable_overrides(tmp_path):
    store = _two_algorithms(tmp_path)
    spec = {"id": "x", "text": "g beats a", "kind": "comparison", "experiment": "exp", "better": "g", "than": "a",
            "basis": "iterations", "readings": [{"id": "r1", "condition": "reading 1", "use": {"g": "b"}},
                                                {"id": "r2", "condition": "reading 2", "use": {"g": "a"}}]}
    rows = judge("paper", spec, store)
    assert [(c.id, c.verdict, c.condition) for c in rows] == [
        ("x:r1", "conditional: held", "reading 1"), ("x:r2", "conditional: not held", "reading 2")]
    c, = judge("paper", {**spec, "readings": None, "better": "b", "not_checkable": "the equations were lost"}, store)
    assert c.verdict == NOT_CHECKABLE and c.evidence.startswith("the equations were lost") and "p_a" in c.numbers
    c, = judge("paper", {**spec, "readings": None, "experiment": "absent"}, store)
    assert c.verdict == NOT_CHECKABLE and "no stored result" in c.evidence
    c, = judge("paper", {"id": "s", "text": "DOF 4", "kind": "statement", "not_checkable": "lost"}, store)
    assert c.verdict == NOT_CHECKABLE and c.evidence == "lost"   # a claim nothing can decide still has its row
    spread = {"id": "v", "text": "a is stabler", "kind": "comparison", "experiment": "exp", "better": "a", "than": "b",
              "quantity": "spread:final_fitness", "basis": "iterations"}
    c, = judge("paper", spread, store)     # |f - median f| per run: b's final values spread less (10^-15 scale)
    assert c.numbers["lower_b"] == "b" and c.verdict == NOT_HELD


def test_a_reconstruction_makes_every_verdict_resting_on_it_conditional_either_way(tmp_path, monkeypatch):
    """Provenance is data: the engine, not a paper module, names the reconstruction in the condition
    of every verdict that rests on it (held or not), and a part fitted to a claim makes it not checkable."""
    from fkopt.reproduce import engine
    store = _two_algorithms(tmp_path)
    data = {"provenance": {"b": {"as": "reconstruction", "name": "B", "chosen": "lost equations, fkopt's choice"},
                           "a": {"as": "printed", "name": "A"},
                           "model": {"as": "reconstruction", "name": "model", "chosen": "fitted", "circular": ["fit"]}}}
    monkeypatch.setattr(engine, "load", lambda paper: data)
    spec = {"id": "x", "text": "b beats a", "kind": "comparison", "experiment": "exp", "better": "b", "than": "a",
            "basis": "iterations"}
    held, = judge("paper", spec, store)
    lost, = judge("paper", {**spec, "basis": "evaluations"}, store)
    assert (held.verdict, lost.verdict) == ("conditional: held", "conditional: not held")
    assert held.condition == lost.condition == "reconstructed B: lost equations, fkopt's choice"
    printed, = judge("paper", {**spec, "better": "a", "than": "a", "also": ["b"]}, store)   # beside: no condition
    assert printed.verdict == NOT_HELD and printed.condition == ""
    fit = {"id": "fit", "text": "a reaches 1e-10", "kind": "magnitude", "experiment": "exp", "algorithms": ["a"],
           "quantity": "final_fitness", "statistic": "median", "below": 1.0, "rests_on": ["model"]}
    c, = judge("paper", fit, store)
    assert c.verdict == NOT_CHECKABLE and c.evidence.startswith("circular: the reconstructed model")
    c, = judge("paper", {**fit, "id": "other"}, store)
    assert c.verdict == "conditional: held" and c.condition == "reconstructed model: fitted"


def test_magnitude_uses_a_statistic_over_all_runs_never_a_maximum(tmp_path):
    store = _two_algorithms(tmp_path)
    spec = {"id": "m", "text": "a reaches 1e-10", "kind": "magnitude", "experiment": "exp", "algorithms": ["a"],
            "quantity": "final_fitness", "statistic": "median", "order": 1e-10, "decades": 0.5}
    c, = judge("paper", spec, store)
    assert c.verdict == HELD and 0.9e-10 < c.numbers["median_a_final_fitness"] < 1.1e-10
    assert judge("paper", {**spec, "order_at_most": 1e-12, "order": None}, store)[0].verdict == NOT_HELD
    with pytest.raises(AssertionError):
        judge("paper", {**spec, "statistic": "max"}, store)


def test_a_significant_opposite_time_is_not_held_even_when_the_printed_difference_is_tiny():
    a, b = np.linspace(100, 110, 8), np.linspace(200, 220, 8)
    assert faster_claim("x", "A", compare("A", a, "B", b)).verdict == HELD
    # the paper prints 361.3 vs 362.4 ms (0.3 %, inside a 10 % spread); fkopt measures B significantly
    # slower: that contradicts "B is shorter", it is not noise; the evidence still says the paper cannot resolve it
    c = faster_claim("x", "B", compare("A", a, "B", b), printed=(361.3, 362.4))
    assert c.verdict == NOT_HELD and "0.3 %" in c.evidence and "n = 8" in c.evidence
    assert c.evidence.startswith("B ") and "slower than A (significant)" in c.evidence
    same = faster_claim("x", "B", compare("A", a, "B", a[::-1] + 0.01), printed=(361.3, 362.4))
    assert same.verdict == WITHIN_NOISE and "no significant difference" in same.evidence


def test_time_to_best_is_judged_over_every_run_not_the_timed_ones(tmp_path):
    """Each run's iterations to best (all 30) x its algorithm's median ms per iteration (5 timed runs)."""
    store = _two_algorithms(tmp_path)
    folder = tmp_path / "paper" / "exp"
    runs = pd.read_csv(folder / "runs.csv")
    runs["iterations_to_best"] = np.where(runs.algorithm == "a", 3, 8) + runs.run % 2   # a reaches its best sooner
    runs.to_csv(folder / "runs.csv", index=False)
    # a's whole run takes 1.5x b's: still a finds its best sooner (3.5 x 15 ms vs 8.5 x 10 ms)
    pd.DataFrame({"case": "c", "algorithm": ["a", "b"] * 5, "run": np.repeat(np.arange(5), 2),
                  "ms": [150, 100, 151, 101, 149, 99, 152, 98, 148, 102]}).to_csv(folder / "timing_runs.csv", index=False)
    spec = {"id": "t", "text": "a finds its best sooner", "kind": "timing", "experiment": "exp", "faster": "a",
            "than": "b", "time_to_best": True}
    c, = judge("paper", spec, store)
    assert c.verdict == HELD and "over all 30 vs 30 runs" in c.evidence and c.numbers["lower_iterations"] == "a"
    assert c.numbers["lower_run_ms"] == "b" and c.numbers["median_a_ms"] < c.numbers["median_b_ms"]


def test_reproduce_never_runs_a_claims_file(tmp_path):
    from fkopt.reproduce.run import plan
    assert is_claims_file(ROOT / "configs" / "mao2017" / "claims.yaml")
    (tmp_path / "p").mkdir()
    shutil.copy(ROOT / "configs" / "mao2017" / "claims.yaml", tmp_path / "p" / "claims.yaml")
    shutil.copy(ROOT / "configs" / "mao2017" / "tab3_floor.yaml", tmp_path / "p" / "tab3_floor.yaml")
    assert [p.path.name for p in plan(tmp_path, tmp_path / "out")] == ["tab3_floor.yaml"]


def test_timed_runs_are_interleaved(monkeypatch):
    """Run k of every algorithm of a case before run k + 1 of any (A B A B ...), warm-ups first."""
    from types import SimpleNamespace as NS

    from fkopt.run import timing
    calls = []
    monkeypatch.setattr(timing, "solve", lambda problem, name, iterations, run_ids, **kw: calls.append(
        (name, iterations, run_ids[0])))
    config = NS(runs=3, population=5, iterations=7, threshold=None, stop_at_threshold=False)
    specs = [(NS(name=n, population=None, iterations=None, start=None, params={}), None, 1) for n in ("a", "b")]
    seconds = timing.time_case(config, specs, per=3)
    timed = [(n, k) for n, it, k in calls if it == 7]
    assert [c[0] for c in calls[:2]] == ["a", "b"] and all(it == 2 for _, it, _ in calls[:2])   # warm-ups
    assert timed == [("a", 0), ("b", 0), ("a", 1), ("b", 1), ("a", 2), ("b", 2)]
    assert [len(s) for s in seconds] == [3, 3]


def test_timed_runs_run_on_the_numpy_reference_path_whatever_solved_the_runs(monkeypatch):
    """Compiled kernels exist for some algorithms only (ABC on 3-RPS, not ACO): a timing claim
    compares algorithms on one implementation path, the numpy reference, and the variable is
    restored afterwards."""
    import os
    from types import SimpleNamespace as NS

    from fkopt.run import timing
    from fkopt.numerics import path
    seen = []
    monkeypatch.setattr(timing, "solve", lambda *a, **kw: seen.append(path.requested()))
    monkeypatch.delenv(path.ENV, raising=False)
    config = NS(runs=2, population=5, iterations=3, threshold=None, stop_at_threshold=False)
    specs = [(NS(name=n, population=None, iterations=None, start=None, params={}), None, 1) for n in ("abc", "aco")]
    timing.time_case(config, specs, per=2)
    assert seen and set(seen) == {"numpy"} and path.ENV not in os.environ and path.requested() == "auto"


# -- issue 41: what a paper printed is data; bases compared like with like; "close" times; stale verdict files --
SPEC = Path(__import__("os").environ.get("FKOPT_SPEC", "/work/shared/SPEC.md"))


def test_a_setting_is_printed_only_where_spec_cites_it():
    """``as`` is derived: an entry that chose anything is a reconstruction, one citing a setting the
    paper's ``printed`` table lacks or carrying a hand-written ``as`` is refused, and a quote SPEC.md
    does not hold under its section is reported."""
    from fkopt.reproduce.engine import derive_provenance, uncited_settings
    data = {"printed": {"spec": "p — a paper", "settings": {"pop": "population 10"}},
            "provenance": {"a": {"name": "A", "printed": ["pop"]},
                           "b": {"name": "B", "printed": ["pop"], "chosen": "limit not printed"}}}
    prov = derive_provenance(data)
    assert (prov["a"]["as"], prov["b"]["as"]) == ("printed", "reconstruction")
    for bad in ({"a": {"name": "A", "printed": ["pop"], "as": "printed"}},      # written by hand
                {"a": {"name": "A", "printed": ["box"]}},                       # not in the printed table
                {"a": {"name": "A"}}):                                          # cites nothing, chose nothing
        with pytest.raises(AssertionError):
            derive_provenance({**data, "provenance": bad})
    spec = "# t\n\n## p — a paper\n- Settings: population\n  10, 600 iterations.\n\n## q\nlimit 5\n"
    assert uncited_settings(data, spec) == []                                   # line breaks aside
    moved = {**data, "printed": {"spec": "q", "settings": data["printed"]["settings"]}}
    assert uncited_settings(moved, spec) == ["pop: 'q' has no 'population 10'"]


@pytest.mark.skipif(not SPEC.is_file(), reason="SPEC.md not on this machine (FKOPT_SPEC points at it)")
def test_every_printed_setting_of_the_five_papers_stands_in_spec():
    from fkopt.reproduce.engine import load, uncited_settings
    text = SPEC.read_text(encoding="utf-8")
    for paper in ("mao2017", "chang2024", "wu2015", "liu2008", "wang7dof"):
        assert uncited_settings(load(paper), text) == [], paper


def test_the_five_papers_unprinted_settings_make_their_parts_reconstructions():
    """The referee's list: liu2008's search box and Newton, LM, the ABC limits, chang2024's PSO clamp."""
    from fkopt.reproduce.engine import load
    kinds = {(p, k): e["as"] for p in ("mao2017", "chang2024", "liu2008", "wang7dof")
             for k, e in load(p)["provenance"].items()}
    for part in [("liu2008", "search-box"), ("liu2008", "nr"), ("liu2008", "nr_clipped"), ("liu2008", "lm"),
                 ("wang7dof", "lm"), ("mao2017", "abc"), ("chang2024", "abc"), ("chang2024", "pso")]:
        assert kinds[part] == "reconstruction", part
    assert kinds[("liu2008", "mechanism")] == kinds[("wang7dof", "mechanism")] == "printed"


def test_close_times_are_judged_by_the_one_timing_rule(tmp_path):
    from fkopt.reproduce.engine import _close
    fast, slow = np.linspace(10, 12, 10), np.linspace(20, 24, 10)
    far = _close("x", compare("A", fast, "B", slow))
    near = _close("x", compare("A", fast, "B", fast[::-1] + 0.05))
    assert (far.verdict, near.verdict) == (NOT_HELD, HELD)
    assert far.evidence.startswith("significantly different") and "rule: rank test" in far.evidence


def test_a_verdict_file_an_older_engine_wrote_fails_check(tmp_path):
    """results/peers held 17 rows of an older engine (columns claim, verdict, "no stored result" for
    claims judged elsewhere): a tree without the experiments a paper's claims rest on gets no verdict
    files, and a stored one there, or one with other columns or rows, fails fkopt check."""
    from fkopt.reproduce.check import verdict_files
    root = tmp_path / "results"
    shutil.copytree(ROOT / "results" / "liu2008" / "newton_starts", root / "liu2008" / "newton_starts")
    (root / "REPORT.md").write_text("a tree written by fkopt reproduce\n")
    exp = Store(root).get("liu2008", "newton_starts")
    assert [(m.file, m.stored) for m in verdict_files(exp)][:1] == [("claims.csv", "missing")]
    for path, df in claims_files(root).items():
        df.to_csv(path, index=False)
    assert verdict_files(exp) == []
    file = root / "liu2008" / "claims.csv"
    pd.read_csv(file, keep_default_na=False)[["claim", "verdict"]].to_csv(file, index=False)   # the old columns
    bad = verdict_files(exp)
    assert [(m.file, m.column) for m in bad] == [("claims.csv", "columns")] and "older engine" in bad[0].rule
    df = claims_files(root)[file]
    df.loc[0, "condition"] = "an older condition"
    df.to_csv(file, index=False)
    assert [(m.file, m.column) for m in verdict_files(exp)] == [("claims.csv", "condition")]
    # a tree of other runs of the paper's mechanism (results/peers): no verdicts of the paper there
    peers = tmp_path / "peers"
    shutil.copytree(ROOT / "results" / "liu2008" / "newton_starts", peers / "liu2008" / "peers")
    assert claims_files(peers) == {}
    pd.DataFrame({"claim": ["Tab. 3/Fig. 4 claims"], "verdict": ["not checkable"]}).to_csv(
        peers / "liu2008" / "claims.csv", index=False)
    bad = verdict_files(Store(peers).get("liu2008", "peers"))
    assert [(m.file, m.stored, m.rerun) for m in bad] == [("claims.csv", "present", "absent")]
