"""Every claim of the five papers: its verdict AND the numbers behind it, from the stored results.

Ranges are wide enough to survive a regeneration with the same seeds (and the documented budgets),
narrow enough that a changed model, algorithm or statistic fails: a verdict that flips, a p-value
that crosses alpha, a median that moves by more than run-to-run noise. Timing claims are not
asserted here (speed is measured, never asserted in a unit test); their logic is tested in
test_claims_logic.py.

``FKOPT_RESULTS`` points the tests at another results tree (default: the repository's results/).
"""
import os
from pathlib import Path

import pytest

from fkopt.reproduce.claims import HELD, NOT_CHECKABLE, NOT_HELD
from fkopt.reproduce.report import paper_module
from fkopt.reproduce.store import Store

ROOT = Path(__file__).resolve().parents[1]
RESULTS = Path(os.environ.get("FKOPT_RESULTS", ROOT / "results"))


def between(lo, hi):
    return lambda v: v is not None and lo <= v <= hi


def below(x):
    return lambda v: v is not None and v < x


def equal(x):
    return lambda v: v == x


SIGNIFICANT = below(0.01)   # a margin under alpha = 0.05

# (paper, start of the claim's text, verdict, {number: check})
EXPECTED = [
    # -- mao2017
    ("mao2017", "Tab. 3: ABC and GABC reach a mean final fitness of 5.41e-17", HELD,
     {"mean_abc": between(3e-17, 1.2e-16), "mean_gabc": between(3e-17, 1.2e-16),
      "std_abc": between(1e-17, 5e-17), "raw_mean_abc": equal(0.0), "raw_mean_gabc": equal(0.0)}),
    ("mao2017", "Tab. 3: GABC is more precise than ABC", NOT_HELD, {"p_iterations": between(0.05, 1.0)}),
    ("mao2017", "Tab. 3: ACO's error is far larger", NOT_CHECKABLE,
     {"p_iterations": SIGNIFICANT, "median_aco": between(1e-13, 1e-10), "median_abc": equal(0.0)}),
    ("mao2017", "Fig. 2: ABC converges", HELD, {"median_iterations_abc": between(140, 175)}),
    ("mao2017", "Fig. 2: GABC (eq. 19 as printed) converges fastest", NOT_HELD,
     {"median_iterations_gabc": between(155, 195), "median_iterations_zhu": between(70, 95),
      "lower_gabc_abc": equal("ABC"), "lower_zhu_abc": equal("GABC (Zhu & Kwong)"), "p_zhu_abc": SIGNIFICANT}),
    ("mao2017", "Tab. 2: ABC and GABC solve every variable", HELD, {"max_mean_abs_error": below(1e-12)}),
    ("mao2017", "Tab. 5: stopping at fitness < 1e-5, ACO cannot", NOT_CHECKABLE, {"success_aco": equal(1.0)}),
    ("mao2017", "Fig. 3: stopping at fitness < 1e-5, GABC converges in fewer iterations", NOT_HELD,
     {"lower_iterations": equal("ABC"), "p_iterations": SIGNIFICANT, "median_gabc": between(70, 92),
      "median_abc": between(58, 76)}),
    ("mao2017", "Tab. 4: at fitness < 1e-5 the absolute errors", NOT_HELD,
     {"max_median_run_abs_error": between(1e-3, 5e-3)}),
    ("mao2017", "Tab. 6: GABC solves all five poses", HELD, {"min_success_rate": equal(1.0)}),
    ("mao2017", "Tab. 6: at that precision every pose variable", NOT_HELD,
     {"max_median_run_abs_error": between(5e-4, 5e-3)}),
    ("mao2017", "Sec. 3: the printed leg lengths", NOT_HELD, {"max_difference_mm": between(0.3335, 0.3345)}),
    ("mao2017", "Solving the printed leg lengths gives the exact solution", HELD,
     {"max_difference_from_exact": below(1e-4)}),
    ("mao2017", "Tab. 2/3: the ACO row solves the same inputs", NOT_HELD,
     {"aco_to_exact": between(0.0077, 0.0078), "aco_to_pose": between(0.1401, 0.1402)}),
    # -- chang2024
    ("chang2024", "Sec. 3.3: the case (25 deg, 34 deg, 23 deg, 360 mm)", HELD,
     {"difference_l1": between(3.4e-4, 3.6e-4), "difference_delta": between(-2e-5, -1.6e-5)}),
    ("chang2024", "Tab. 1: mean error over 30 runs of order", NOT_CHECKABLE,
     {"mean_abc": between(1e-16, 1e-13), "mean_pso": between(1e-5, 1e-3), "mean_pabc": between(1e-13, 1e-10)}),
    ("chang2024", "Tab. 1: P-ABC is more precise than ABC", NOT_HELD,
     {"lower_iterations": equal("ABC"), "p_iterations": SIGNIFICANT, "lower_evaluations": equal("P-ABC"),
      "p_evaluations": SIGNIFICANT, "evaluations": between(45000, 45200)}),
    ("chang2024", "Tab. 1 / Sec. 4: P-ABC is 10 orders of magnitude", NOT_HELD,
     {"lower_iterations": equal("P-ABC"), "p_iterations": SIGNIFICANT, "orders": between(6.0, 9.0)}),
    ("chang2024", "Fig. 7: in the first 150 iterations ABC converges faster", HELD,
     {"lower_abc_pso": equal("ABC"), "lower_abc_pabc": equal("ABC"), "p_abc_pso": SIGNIFICANT}),
    ("chang2024", "Fig. 7: after iteration 150 PSO converges slowly", HELD,
     {"median_drop_pso": between(1.0, 3.0), "median_drop_pabc": between(8.0, 11.0), "p_pabc_pso": SIGNIFICANT}),
    ("chang2024", "Fig. 7: after iteration 150 ABC's curve stays flat", NOT_HELD,
     {"median_drop_abc": between(6.5, 9.5)}),
    ("chang2024", "Fig. 7: at iteration 300 P-ABC's fitness is far below", NOT_HELD,
     {"lower_pabc_abc": equal("ABC"), "lower_pabc_pso": equal("P-ABC")}),
    ("chang2024", "Tab. 2: P-ABC solves every one of 50 poses", NOT_CHECKABLE,
     {"median_fitness": between(1e-13, 1e-10)}),
    ("chang2024", "Tab. 2 (beyond Tab. 1's single case)", NOT_HELD,
     {"lower_pabc_abc": equal("ABC"), "lower_pabc_pso": equal("P-ABC"), "p_pabc_abc": SIGNIFICANT}),
    # -- wu2015
    ("wu2015", "Sec. 5: (20 mm, 30 mm, 15 deg) has inputs", HELD, {}),
    ("wu2015", "Sec. 5: the example's answer", NOT_HELD, {}),
    ("wu2015", "Sec. 4.2: within the workspace the forward solution is unique", NOT_CHECKABLE,
     {"mirrors_in_workspace": equal(6), "runs_on_mirror": between(40, 120)}),
    ("wu2015", "Sec. 5: the improved ACO solves the example", HELD, {}),
    ("wu2015", "Tab. 1: the improved ACO solves the five poses", NOT_CHECKABLE,
     {"worst_median_relative_error": between(1e-4, 1e-2)}),
    ("wu2015", "Figs. 5-6: after 500 and 1000 moves", NOT_CHECKABLE, {"mean_ant_fitness": between(0.05, 2.0)}),
    ("wu2015", "Fig. 7: the best pheromone rises", HELD, {}),
    ("wu2015", "Sec. 5/6: the improved ACO avoids the influence", NOT_CHECKABLE,
     {"share_on_target": between(0.3, 0.75)}),
    ("wu2015", "Tab. 2: Newton-Raphson's result depends strongly", NOT_HELD, {}),
    ("wu2015", "Tab. 2: the four starts with theta = 10 deg", NOT_HELD, {}),
    ("wu2015", "Tab. 1 vs Tab. 2: the improved ACO gives more precise", NOT_HELD,
     {"lower": equal("NR"), "p": SIGNIFICANT, "median_nr": below(1e-12), "median_aco": between(1e-7, 1e-3)}),
    # -- liu2008
    ("liu2008", "Abstract/Sec. 4: with 80 particles PSO reaches 0.5 um", NOT_HELD,
     {"median_iterations": between(72, 100), "success_rate": equal(1.0)}),
    ("liu2008", "Tab. 3/Fig. 4: PSO finds the probe pose", HELD, {"position_error_um": below(1.0)}),
    ("liu2008", "Tab. 3: the printed pose is the forward solution", HELD, {"largest_difference": below(5e-7)}),
    ("liu2008", "Sec. 5: PSO overcomes numerical methods' dependence", NOT_HELD,
     {"success_lm": between(0.9, 1.0), "p": between(0.05, 1.0)}),
    ("liu2008", "Sec. 5: PSO gives high computing precision", HELD, {"median_fitness_pso": below(1e-12)}),
    # -- wang7dof
    ("wang7dof", "Tab. 2: the printed joint solutions", NOT_HELD,
     {"position_error_abc": between(85.8, 86.0), "position_error_pso": between(126.0, 126.2)}),
    ("wang7dof", "Tab. 3: ABC reaches its best solution in fewer iterations", HELD,
     {"lower": equal("ABC"), "p": SIGNIFICANT, "median_abc": between(440, 500), "median_pso": between(470, 500),
      "lower_evaluations": equal("ABC"), "p_evaluations": SIGNIFICANT}),
    ("wang7dof", "Tab. 3: both reach position errors of a few 1e-3 mm", NOT_HELD,
     {"median_position_error_abc": between(0.5, 5.0), "median_position_error_pso": between(1e-4, 0.1)}),
    ("wang7dof", "Abstract/Sec. 4, Fig. 6a: ABC's position error is smaller", NOT_HELD,
     {"lower": equal("PSO"), "p": SIGNIFICANT, "median_abc_mm": between(0.5, 5.0),
      "median_pso_mm": between(1e-4, 0.1)}),
    ("wang7dof", "Abstract/Fig. 6a: ABC's position error settles below 1e-4", NOT_HELD,
     {"median_position_error_abc": between(0.5, 5.0)}),
    ("wang7dof", "Sec. 3: the solutions reach the target", NOT_HELD,
     {"share_abc": equal(0.0), "share_pso": equal(0.0), "euler_error_abc": between(1.0, 10.0),
      "euler_error_pso": between(3.0, 30.0)}),
    ("wang7dof", "Eq. 10: the PSO as printed", NOT_HELD,
     {"median_eq10_mm": between(1.0, 100.0), "p": SIGNIFICANT}),
    ("wang7dof", "Introduction: swarm search is the better route", NOT_HELD,
     {"lower": equal("LM"), "p": SIGNIFICANT}),
    ("wang7dof", "Fig. 7a: on random poses ABC's position error is smaller", NOT_HELD,
     {"lower": equal("PSO"), "p": SIGNIFICANT}),
]


@pytest.fixture(scope="module")
def claims():
    store = Store(RESULTS)
    return {paper: paper_module(paper).claims(store) for paper in {e[0] for e in EXPECTED}}


@pytest.mark.parametrize("paper,start,verdict,checks", EXPECTED, ids=[f"{e[0]}: {e[1][:50]}" for e in EXPECTED])
def test_claim_verdict_and_numbers(claims, paper, start, verdict, checks):
    found = [c for c in claims[paper] if c.text.startswith(start)]
    assert len(found) == 1, f"{paper}: no single claim starting with {start!r}: {[c.text for c in claims[paper]]}"
    c = found[0]
    assert c.verdict == verdict, f"{c.text}: {c.verdict} ({c.evidence})"
    for key, ok in checks.items():
        assert key in c.numbers, f"{c.text}: no number {key!r} in {sorted(c.numbers)}"
        assert ok(c.numbers[key]), f"{c.text}: {key} = {c.numbers[key]!r} ({c.evidence})"


def test_every_claim_is_covered(claims):
    """A new or renamed claim needs its expectation here."""
    for paper, cl in claims.items():
        starts = [e[1] for e in EXPECTED if e[0] == paper]
        for c in cl:
            assert any(c.text.startswith(s) for s in starts), f"{paper}: claim without a test: {c.text}"


def test_stored_verdicts_match(claims):
    """results/<paper>/claims.csv holds the verdicts that fkopt check guards."""
    import pandas as pd
    for paper, cl in claims.items():
        stored = pd.read_csv(RESULTS / paper / "claims.csv")
        assert dict(zip(stored.claim, stored.verdict)) == {c.text: c.verdict for c in cl}
