"""Every claim of the five papers (configs/<paper>/claims.yaml): its verdict AND the numbers behind it,
judged by the one engine from the stored results.

Ranges are wide enough to survive a regeneration with the same seeds, narrow enough that a changed
model, algorithm or statistic fails. Timing claims are not asserted here (speed is measured, never
asserted in a unit test); their logic is tested in test_claims_logic.py. A claim whose result is not
stored yet (a results tree older than its config, e.g. before wang7dof's Tab. 3 ran eq. 10's PSO) is
skipped, never passed.

``FKOPT_RESULTS`` points the tests at another results tree (default: the repository's results/).
"""
import os
import re
from pathlib import Path

import pandas as pd
import pytest

from fkopt.reproduce.claims import HELD, NOT_CHECKABLE, NOT_HELD
from fkopt.reproduce.engine import ALGORITHM_FIELDS, judge_paper, load
from fkopt.reproduce.store import Store

ROOT = Path(__file__).resolve().parents[1]
RESULTS = Path(os.environ.get("FKOPT_RESULTS", ROOT / "results"))
C_HELD, C_NOT_HELD = "conditional: held", "conditional: not held"


def between(lo, hi):
    return lambda v: v is not None and lo <= v <= hi


def below(x):
    return lambda v: v is not None and v < x


def equal(x):
    return lambda v: v == x


SIGNIFICANT = below(0.01)   # a margin under alpha = 0.05

# (paper, claim id, verdict, {number: check})
EXPECTED = [
    ("mao2017", "tab3-floor:karaboga", C_HELD, {"mean_abc_final_fitness": between(3e-17, 1.2e-16)}),
    # raw f, the other reading of the paper's greedy selection: both reach 0, not the printed ~5e-17
    ("mao2017", "tab3-floor:raw-f", C_NOT_HELD, {"mean_abc_final_fitness": equal(0.0)}),
    ("mao2017", "tab3-gabc-more-precise:eq19", C_NOT_HELD, {"p_abc": between(0.05, 1.0)}),
    ("mao2017", "tab3-gabc-more-precise:zhu-kwong", C_NOT_HELD, {"p_abc": between(0.05, 1.0)}),
    ("mao2017", "tab3-gabc-more-precise:eq19:raw-f", C_NOT_HELD, {"p_abc": equal(1.0)}),
    ("mao2017", "tab3-gabc-more-precise:zhu-kwong:raw-f", C_NOT_HELD, {"p_abc": equal(1.0)}),
    ("mao2017", "tab3-aco-larger", C_HELD, {"p_aco": SIGNIFICANT, "median_abc": equal(0.0)}),
    ("mao2017", "fig2-abc-170", C_HELD, {"median_iterations_abc": between(140, 175)}),
    ("mao2017", "fig2-gabc-fastest:eq19", C_NOT_HELD,
     {"median_iterations_gabc": between(155, 195), "lower_iterations": equal("ABC")}),
    ("mao2017", "fig2-gabc-fastest:zhu-kwong", C_HELD,
     {"median_iterations_gabc_zhu2010": between(70, 95), "p_iterations": SIGNIFICANT}),
    # the reconstructed ACO is slow (528 vs 110 iterations to 1e-10) but not flat (10 decades after iteration 150)
    ("mao2017", "fig2-aco-slow:vs-abc", C_HELD, {"lower_aco": equal("ABC"), "p_aco": SIGNIFICANT}),
    ("mao2017", "fig2-aco-slow:vs-gabc", C_HELD, {"lower_aco": equal("GABC (eq. 19)"), "p_aco": SIGNIFICANT}),
    ("mao2017", "fig2-aco-flat", C_NOT_HELD, {"median_aco_log10_change": between(-13.0, -5.0)}),
    ("mao2017", "tab2-below-1e-10:raw-f", C_HELD, {"mean_abc_z": below(1e-12), "mean_gabc_beta": below(1e-12)}),
    # Karaboga's selection, the reading the report uses for Tab. 3: errors of 1e-9 (the paper prints 5e-10)
    ("mao2017", "tab2-below-1e-10:karaboga", C_NOT_HELD,
     {"mean_abc_z": between(1e-9, 5e-9), "mean_gabc_alpha": between(5e-10, 3e-9)}),
    ("mao2017", "tab5-aco-fails", C_NOT_HELD, {"median_aco_final_fitness": below(1e-5)}),
    ("mao2017", "fig3-gabc-fewer-iterations:eq19", C_NOT_HELD,
     {"lower_abc": equal("ABC"), "p_abc": SIGNIFICANT, "median_gabc": between(70, 92), "median_abc": between(58, 76)}),
    ("mao2017", "fig3-gabc-fewer-iterations:zhu-kwong", C_HELD,
     {"lower_abc": equal("GABC (Zhu & Kwong)"), "p_abc": SIGNIFICANT}),
    ("mao2017", "tab4-errors-1e-4", C_HELD, {"median_abc_z": between(1e-4, 1e-3)}),
    ("mao2017", "tab6-all-poses", C_HELD, {}),
    ("mao2017", "tab6-errors", C_HELD, {}),
    ("mao2017", "printed-legs-belong-to-pose", NOT_HELD, {"max_difference_mm": between(0.3335, 0.3345)}),
    ("mao2017", "printed-legs-exact-solution", HELD, {"max_difference_from_exact": below(1e-4)}),
    ("mao2017", "aco-row-same-inputs", NOT_HELD,
     {"aco_to_exact": between(0.0077, 0.0078), "aco_to_pose": between(0.1401, 0.1402)}),
    # -- chang2024: every comparison rests on the reconstructed P-ABC
    ("chang2024", "case-inputs", NOT_CHECKABLE,
     {"difference_l1": between(3.4e-4, 3.6e-4), "difference_delta": between(-2e-5, -1.6e-5)}),
    ("chang2024", "dof-4-coupling-2", NOT_CHECKABLE, {}),
    ("chang2024", "fig3-solidworks", NOT_CHECKABLE, {}),
    ("chang2024", "simpler-than-ref25", NOT_CHECKABLE, {}),
    ("chang2024", "tab1-orders", NOT_CHECKABLE, {"mean_pso_final_fitness": between(1e-5, 1e-3)}),
    ("chang2024", "tab1-pabc-vs-abc", C_NOT_HELD,
     {"lower_abc": equal("ABC"), "p_abc": SIGNIFICANT, "lower_evaluations_abc": equal("P-ABC"),
      "p_evaluations_abc": SIGNIFICANT, "bases_disagree": equal(True)}),
    ("chang2024", "tab1-pabc-10-orders", C_NOT_HELD, {"lower_pso": equal("P-ABC"), "orders_pso": between(6.0, 9.0)}),
    ("chang2024", "fig7-abc-fastest-first-150", C_HELD, {"lower_pso": equal("ABC"), "lower_pabc": equal("ABC")}),
    ("chang2024", "fig7-pabc-accelerates", C_HELD, {"lower_pso": equal("P-ABC"), "p_pso": SIGNIFICANT}),
    ("chang2024", "fig7-abc-flat", C_NOT_HELD, {"median_abc_log10_change": between(-9.5, -6.5)}),
    ("chang2024", "fig7-pabc-lowest-at-300", C_NOT_HELD, {"lower_abc": equal("ABC"), "lower_pso": equal("P-ABC")}),
    ("chang2024", "tab2-pabc-1e-20", NOT_CHECKABLE, {"median_pabc_final_fitness": between(1e-13, 1e-10)}),
    # -- wu2015: the reconstructed geometry's mirror decides most claims
    ("wu2015", "dof-3", HELD, {"mobility": equal(3), "jacobian_rank": equal(3)}),
    ("wu2015", "example-inputs", NOT_CHECKABLE, {"max_difference_mm": below(5e-5)}),
    ("wu2015", "example-printed-fitness", C_NOT_HELD, {"fitness": between(5e-7, 8e-7)}),
    ("wu2015", "unique-solution", C_NOT_HELD, {"mirrors_in_workspace": equal(6), "runs_on_mirror": between(40, 120)}),
    # half of the runs end on the mirror pose: solved on fitness alone, not on the paper's pose
    ("wu2015", "example-solved:on-target", C_NOT_HELD, {"mean_aco_on_target": between(0.3, 0.5)}),
    ("wu2015", "example-solved:any-solution", C_HELD, {"mean_aco_any_solution": between(0.95, 1.0)}),
    ("wu2015", "tab1-relative-errors", C_NOT_HELD, {"worst_median_relative_error": between(1e-4, 1e-2)}),
    ("wu2015", "figs5-6-ants-gather", C_NOT_HELD, {"mean_ant_fitness": between(0.05, 2.0)}),
    ("wu2015", "fig7-pheromone", C_HELD, {}),
    ("wu2015", "start-independent", C_NOT_HELD, {"share_on_target": between(0.3, 0.75)}),
    ("wu2015", "nr-depends-on-start", C_NOT_HELD, {"max_abs_error": below(1e-10)}),
    ("wu2015", "nr-theta10-differ", C_NOT_HELD, {"spread": below(1e-6)}),
    ("wu2015", "aco-more-precise-than-nr", C_NOT_HELD, {"lower": equal("NR"), "median_nr": below(1e-12)}),
    ("wu2015", "other-mechanisms", C_HELD, {"median_aco_final_fitness": below(1e-5)}),
    # -- liu2008
    # liu2008's search box (and PSO's initial velocities) are fkopt's: every verdict on a run is conditional
    ("liu2008", "iterations-55", C_NOT_HELD, {"median_iterations_pso": between(72, 100)}),
    ("liu2008", "micrometre-precision", C_HELD, {"mean_pso_x": below(1e-6)}),
    ("liu2008", "printed-pose-is-solution", HELD, {"largest_difference": below(5e-7)}),
    # plain Newton from 300 random starts in fkopt's box misses 11 (never reaches 0.5 um; the 12th the
    # referee counted was the Tab. 3 pose in equivalent Euler angles); clipped to the box it misses none
    ("liu2008", "start-independence:plain-newton", C_HELD,
     {"lower_nr": equal("PSO"), "p_nr": SIGNIFICANT, "median_nr": equal(0.0)}),
    ("liu2008", "start-independence:clipped-newton", C_NOT_HELD, {"lower_nr_clipped": equal(None),
                                                                   "p_nr_clipped": equal(1.0)}),
    ("liu2008", "high-precision", C_HELD, {"median_pso_final_fitness": below(1e-12)}),
    # -- wang7dof: judged against the paper's eq. 10 PSO
    ("wang7dof", "tab2-printed-solutions-reach-target", NOT_HELD,
     {"position_error_abc": between(85.8, 86.0), "position_error_pso": between(126.0, 126.2)}),
    ("wang7dof", "tab3-fewer-iterations-to-best:last-improvement:eq10", C_NOT_HELD,
     {"lower_pso_eq10": equal("PSO (eq. 10)"), "p_pso_eq10": SIGNIFICANT}),
    ("wang7dof", "tab3-fewer-iterations-to-best:last-improvement:constriction", C_HELD,
     {"lower_pso": equal("ABC"), "p_pso": SIGNIFICANT}),
    ("wang7dof", "tab3-fewer-iterations-to-best:within-1pct:eq10", C_NOT_HELD,
     {"lower_pso_eq10": equal("PSO (eq. 10)")}),
    ("wang7dof", "tab3-fewer-iterations-to-best:within-1pct:constriction", C_NOT_HELD,
     {"lower_pso": equal("PSO (constriction)")}),
    ("wang7dof", "tab3-few-1e-3-mm:eq10", C_NOT_HELD, {"median_abc_position_error": between(0.5, 5.0)}),
    ("wang7dof", "tab3-few-1e-3-mm:constriction", C_NOT_HELD,
     {"median_abc_position_error": between(0.5, 5.0), "median_pso_position_error": between(5e-4, 5e-3)}),
    # both candidate reconstructions of the paper's PSO: eq. 10 with fkopt's constants misses Tab. 3's PSO
    # error (12 mm vs 3.71e-3), the constriction PSO matches it and beats ABC
    ("wang7dof", "abc-more-precise:eq10", C_HELD,
     {"lower_pso_eq10": equal("ABC"), "p_pso_eq10": SIGNIFICANT, "median_pso_eq10": between(3.0, 40.0)}),
    # the bases compared like with like: on f ABC is lower at equal iterations and at equal evaluations
    # (no "bases disagree"), on the position error, the claim's quantity, the constriction PSO is lower
    ("wang7dof", "abc-more-precise:constriction", C_NOT_HELD,
     {"lower_pso": equal("PSO (constriction)"), "p_pso": SIGNIFICANT, "lower_f_iterations_pso": equal("ABC"),
      "lower_evaluations_pso": equal("ABC")}),
    # the ABC as printed (eqs. 7-8: phi in [0, 1), quality 1/f) decides the same way
    ("wang7dof", "abc-more-precise:printed-abc:eq10", C_HELD,
     {"lower_pso_eq10": equal("ABC (eqs. 7-8)"), "p_pso_eq10": SIGNIFICANT}),
    ("wang7dof", "abc-more-precise:printed-abc:constriction", C_NOT_HELD,
     {"lower_pso": equal("PSO (constriction)"), "p_pso": SIGNIFICANT}),
    ("wang7dof", "abc-below-1e-4-mm:fkopt-abc", C_NOT_HELD, {"median_abc_position_error": between(0.5, 5.0)}),
    ("wang7dof", "abc-below-1e-4-mm:printed-abc", C_NOT_HELD,
     {"median_abc_printed_position_error": between(0.5, 10.0)}),
    ("wang7dof", "fig6a-pso-below-1e-3-mm:eq10", C_NOT_HELD, {"median_pso_eq10_position_error": between(1.0, 100.0)}),
    ("wang7dof", "fig6a-pso-below-1e-3-mm:constriction", C_NOT_HELD,
     {"median_pso_position_error": between(1e-3, 3e-3)}),
    ("wang7dof", "abc-more-stable:eq10", C_HELD, {"lower_pso_eq10": equal("ABC"), "p_pso_eq10": SIGNIFICANT}),
    ("wang7dof", "abc-more-stable:constriction", C_NOT_HELD, {"lower_pso": equal("PSO (constriction)")}),
    ("wang7dof", "abc-more-robust:eq10", C_HELD, {"lower_pso_eq10": equal("ABC"), "p_pso_eq10": SIGNIFICANT}),
    ("wang7dof", "abc-more-robust:constriction", C_NOT_HELD, {"lower_pso": equal("PSO (constriction)")}),
    ("wang7dof", "requirement-met:eq10", C_NOT_HELD, {"mean_abc_meets_requirement": equal(0.0)}),
    ("wang7dof", "requirement-met:constriction", C_NOT_HELD, {"mean_abc_meets_requirement": equal(0.0)}),
    ("wang7dof", "eq10-pso-reaches-tab3", C_NOT_HELD, {"median_pso_eq10_position_error": between(1.0, 100.0)}),
    ("wang7dof", "fig7a-abc-more-precise:eq10", C_HELD, {"lower_pso_eq10": equal("ABC"), "p_pso_eq10": SIGNIFICANT}),
    ("wang7dof", "fig7a-abc-more-precise:constriction", C_NOT_HELD,
     {"lower_pso": equal("PSO (constriction)"), "p_pso": SIGNIFICANT}),
]


@pytest.fixture(scope="module")
def claims():
    store = Store(RESULTS)
    return {paper: judge_paper(paper, store)[0] for paper in {e[0] for e in EXPECTED}}


@pytest.mark.parametrize("paper,cid,verdict,checks", EXPECTED, ids=[f"{e[0]}: {e[1]}" for e in EXPECTED])
def test_claim_verdict_and_numbers(claims, paper, cid, verdict, checks):
    found = [c for c in claims[paper] if c.id == cid]
    assert len(found) == 1, f"{paper}: no single claim {cid!r}: {[c.id for c in claims[paper]]}"
    c = found[0]
    if c.evidence.startswith("no stored result"):
        pytest.skip(f"{paper}/{cid}: {c.evidence} (regenerate results/)")
    assert c.verdict == verdict, f"{c.id}: {c.verdict} ({c.evidence})"
    if "lower_f_iterations_pso" in checks:     # bases compared on f at both: they agree here
        assert "bases_disagree" not in c.numbers and "bases disagree" not in c.evidence, c.evidence
    for key, ok in checks.items():
        assert key in c.numbers, f"{c.id}: no number {key!r} in {sorted(c.numbers)}"
        assert ok(c.numbers[key]), f"{c.id}: {key} = {c.numbers[key]!r} ({c.evidence})"


def test_every_claim_is_covered(claims):
    """A new or renamed claim needs its expectation here."""
    for paper, cl in claims.items():
        ids = {e[1] for e in EXPECTED if e[0] == paper}
        assert {c.id for c in cl} == ids, f"{paper}: claims without a test or tests without a claim"


def test_evidence_states_the_outcome_before_the_rule(claims):
    """The measured outcome comes first, the rule after it: no row reads 'held within' (or any
    verdict word) as its rule, least of all a row that is not held."""
    for paper, cl in claims.items():
        for c in cl:
            if c.evidence.startswith("no stored result") or c.kind == "statement":
                continue
            assert "held within" not in c.evidence, f"{c.id}: {c.evidence}"
            assert "rule" in c.evidence, f"{c.id}: evidence without its rule: {c.evidence}"
            if c.verdict.endswith("not held"):
                assert "outside" in c.evidence or re.search(r"\bnot\b|slower|faster|higher than", c.evidence), \
                    f"{c.id}: a row not held whose evidence does not say what failed: {c.evidence}"


def test_claims_files_declare_every_field():
    """Every claim in claims.yaml says where it stands and what it is judged against."""
    for paper in ("mao2017", "chang2024", "wu2015", "liu2008", "wang7dof"):
        data = load(paper)
        assert data["title"] and data["notes"] and data["experiments"]
        for c in data["claims"]:
            assert c["id"] and c["text"] and c["kind"], c
            # fkopt's own findings are never attributed to the paper (liu2008's PSO-vs-Newton time: the paper's
            # "high computing speed" names no comparator)
            assert c["id"].startswith("fkopt-") == c["text"].startswith("fkopt's own"), f"{paper}/{c['id']}"
            if c["kind"] == "comparison":
                assert c.get("basis") in ("iterations", "evaluations"), f"{paper}/{c['id']}: no budget basis"
            if c["kind"] == "magnitude":
                assert c.get("statistic") in ("mean", "median"), f"{paper}/{c['id']}: statistic over all runs"
            # provenance is data: every algorithm a verdict rests on says whether it is printed or reconstructed
            prov = data.get("provenance") or {}
            for reading in c.get("readings") or [{}]:
                use = reading.get("use") or {}
                for f in ALGORITHM_FIELDS:
                    for a in ([c[f]] if isinstance(c.get(f), str) else c.get(f) or []):
                        key = use.get(a, a)
                        assert key in prov, f"{paper}/{c['id']}: {key} has no provenance entry"
                        assert prov[key]["as"] in ("printed", "reconstruction"), f"{paper}: {key}"
                for part in c.get("rests_on") or []:
                    assert part in prov, f"{paper}/{c['id']}: rests on {part}, which has no provenance entry"


def test_stored_verdicts_match(claims):
    """results/<paper>/claims.csv holds the verdicts that fkopt check guards (after a regeneration)."""
    for paper, cl in claims.items():
        stored = pd.read_csv(RESULTS / paper / "claims.csv", keep_default_na=False)
        if "id" not in stored:
            pytest.skip("results/ predates claim ids (regenerate results/)")
        assert dict(zip(stored["id"], stored.verdict)) == {c.id: c.verdict for c in cl}
