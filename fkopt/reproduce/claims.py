"""Claims of a paper, judged against fkopt's stored results: the verdict vocabulary and its rules.

Verdicts (:data:`RULES` is printed in the report's preamble):

* **held** / **not held** -- fkopt's numbers support / contradict the claim;
* **not checkable** -- the claim rests on something the paper does not print (a reconstructed
  geometry, lost equations or tables), so fkopt's numbers can neither support nor refute it;
* **within noise** -- a timing difference inside the measured run-to-run spread.

Claims comparing two algorithms are decided by a two-sided Mann-Whitney rank test over the runs
(:func:`compare`, alpha = 0.05; identical samples are no difference), never by two medians
alone, at equal iterations *and* at equal function evaluations (:func:`at_evaluations`, from
``trace.csv.gz``). The verdict follows the budget measure the paper used; the other is shown beside.

Every claim carries the numbers behind its verdict (:attr:`Claim.numbers`): the tests assert them,
and ``claims.csv`` (one per paper, written by ``fkopt report``) stores the verdicts that
``fkopt check`` compares (:func:`verdict_changes`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

HELD, NOT_HELD, NOT_CHECKABLE, WITHIN_NOISE = "held", "not held", "not checkable", "within noise"
VERDICTS = (HELD, NOT_HELD, NOT_CHECKABLE, WITHIN_NOISE)
ALPHA = 0.05

RULES = [
    "*held* / *not held*: fkopt's numbers support / contradict the claim.",
    "*not checkable*: the claim rests on something the paper does not print (a reconstructed "
    "geometry, lost equations or tables), so fkopt's numbers can neither support nor refute it; "
    "fkopt's numbers are shown anyway.",
    "*within noise*: a timing difference inside the measured run-to-run spread (timing claims, "
    "TIMING.md only).",
    f"A claim that one algorithm beats another is decided by a two-sided Mann-Whitney rank test over "
    f"the runs at alpha = {ALPHA} (p-value shown; identical samples count as no difference), never by "
    "two medians alone. It is judged at equal iterations and at equal function evaluations (each "
    "run's best-so-far after the cheaper algorithm's evaluations); the verdict follows the budget the "
    "paper used (all five papers give every algorithm the same number of iterations), the other is "
    "shown beside it.",
]


@dataclass
class Claim:
    text: str          # the paper's claim, in its own terms
    verdict: str       # one of VERDICTS
    evidence: str      # fkopt's numbers that decide it
    numbers: dict = field(default_factory=dict)   # the numbers behind the verdict (tests, claims.csv)

    def __post_init__(self):
        assert self.verdict in VERDICTS, self.verdict


def verdict(ok) -> str:
    return HELD if bool(ok) else NOT_HELD


def missing(text: str, what: str) -> Claim:
    return Claim(text, NOT_CHECKABLE, f"no stored result for {what}")


def g(x, digits: int = 3) -> str:
    """Compact number formatting for evidence strings."""
    if x is None or (isinstance(x, float) and np.isnan(x)):
        return "n/a"
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    return f"{x:.{digits}g}"


def p_text(p: float) -> str:
    return f"p = {p:.2g}" if p >= 1e-4 else "p < 1e-4"


# -- comparing two algorithms over runs ----------------------------------------------------------
@dataclass
class Comparison:
    """Two samples of per-run values (lower is better), tested two-sided."""

    a: str
    b: str
    values_a: np.ndarray
    values_b: np.ndarray
    p: float

    @property
    def median_a(self) -> float:
        return float(np.median(self.values_a)) if self.values_a.size else float("nan")

    @property
    def median_b(self) -> float:
        return float(np.median(self.values_b)) if self.values_b.size else float("nan")

    @property
    def lower(self) -> str | None:
        """The significantly lower sample's name, or None (no difference at ALPHA)."""
        if self.p >= ALPHA:
            return None
        return self.a if _u_lower(self.values_a, self.values_b) else self.b

    def text(self, fmt=g) -> str:
        return (f"median {self.a} {fmt(self.median_a)} vs {self.b} {fmt(self.median_b)}, {p_text(self.p)} "
                f"({len(self.values_a)} vs {len(self.values_b)} runs)")


def _u_lower(a: np.ndarray, b: np.ndarray) -> bool:
    """Does ``a`` tend to be lower than ``b`` (probability of superiority < 1/2)?"""
    a, b = np.asarray(a, float), np.asarray(b, float)
    less = (a[:, None] < b[None, :]).sum() + 0.5 * (a[:, None] == b[None, :]).sum()
    return less > a.size * b.size / 2


def compare(a: str, values_a, b: str, values_b) -> Comparison:
    """Two-sided Mann-Whitney U test; identical samples are no difference (p = 1)."""
    from scipy.stats import mannwhitneyu
    va, vb = np.asarray(values_a, float), np.asarray(values_b, float)
    if va.size == 0 or vb.size == 0:   # nothing to compare: no evidence of a difference
        p = 1.0
    elif np.array_equal(np.sort(va), np.sort(vb)) or np.unique(np.concatenate([va, vb])).size == 1:
        p = 1.0
    else:
        p = float(mannwhitneyu(va, vb, alternative="two-sided").pvalue)
    return Comparison(a, b, va, vb, p)


def at_iteration(exp, algo: str, iteration: int | None = None, case: str | None = None) -> np.ndarray:
    """Per-run best-so-far fitness after ``iteration`` (default: the end) from trace.csv.gz/runs.csv."""
    if iteration is None or not exp.has("trace.csv.gz"):
        r = exp.table("runs")
        r = r[r.algorithm == algo] if case is None else r[(r.algorithm == algo) & (r["case"] == case)]
        return r.sort_values("run").final_fitness.to_numpy(float)
    return _from_trace(exp, algo, "iteration", iteration, case)


def at_evaluations(exp, algo: str, evaluations: float, case: str | None = None) -> np.ndarray:
    """Per-run best-so-far fitness after ``evaluations`` function evaluations (trace.csv.gz)."""
    return _from_trace(exp, algo, "evaluations", evaluations, case)


def _from_trace(exp, algo, column, budget, case) -> np.ndarray:
    t = exp.table("trace")
    t = t[t.algorithm == algo] if case is None else t[(t.algorithm == algo) & (t["case"] == case)]
    out = []
    for _, grp in t.groupby("run", sort=True):
        before = grp[grp[column] <= budget]
        out.append(float(before.best_fitness.iloc[-1]) if len(before) else float("inf"))
    return np.asarray(out)


def first_below(exp, algo: str, level: float, case: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per run: (iteration, evaluations) at which the best-so-far first went below ``level``
    (inf where it never did), from trace.csv.gz."""
    t = exp.table("trace")
    t = t[t.algorithm == algo] if case is None else t[(t.algorithm == algo) & (t["case"] == case)]
    its, evs = [], []
    for _, grp in t.groupby("run", sort=True):
        hit = grp[grp.best_fitness < level]
        its.append(float(hit.iteration.iloc[0]) if len(hit) else np.inf)
        evs.append(float(hit.evaluations.iloc[0]) if len(hit) else np.inf)
    return np.asarray(its), np.asarray(evs)


def evaluations_at(exp, algo: str, iteration: int | None = None, case: str | None = None) -> float:
    """Evaluations spent after ``iteration``: mean over runs (convergence.csv); at the end (default)
    the median over runs (runs.csv)."""
    if iteration is None:
        r = exp.table("runs")
        r = r[r.algorithm == algo] if case is None else r[(r.algorithm == algo) & (r["case"] == case)]
        return float(r.evaluations.median())
    c = exp.table("convergence")
    c = c[(c.algorithm == algo) & (c.iteration == iteration)]
    if case is not None:
        c = c[c["case"] == case]
    return float(c.mean_evaluations.iloc[0])


def equal_budget(exp, a: str, b: str, names: dict[str, str], case: str | None = None,
                 iteration: int | None = None) -> tuple[Comparison, Comparison | None, float]:
    """(equal iterations, equal evaluations, the evaluations used) comparisons of ``a`` vs ``b``.

    Equal iterations: each run's best-so-far after ``iteration`` (default: the end). Equal
    evaluations: each run's best-so-far after the evaluations the cheaper of the two spent in
    those iterations (median over its runs); None without a stored trace.
    """
    budget = min(evaluations_at(exp, x, iteration, case) for x in (a, b))
    it = compare(names.get(a, a), at_iteration(exp, a, iteration, case), names.get(b, b),
                 at_iteration(exp, b, iteration, case))
    if not exp.has("trace.csv.gz"):
        return it, None, budget
    evc = compare(names.get(a, a), at_evaluations(exp, a, budget, case), names.get(b, b),
                  at_evaluations(exp, b, budget, case))
    return it, evc, budget


def better_claim(text: str, better: str, it: Comparison, ev: Comparison | None, budget: float,
                 iterations: int, paper_measure: str = "iterations") -> Claim:
    """'``better`` is more precise than the other': held iff significantly lower on the paper's measure."""
    decisive = it if paper_measure == "iterations" or ev is None else ev
    ev_text = ev.text() if ev is not None else "not stored (no per-run trace for experiments of many cases)"
    evidence = (f"equal iterations ({iterations}): {it.text()}; equal evaluations ({budget:.0f}): {ev_text}; "
                f"verdict on equal {paper_measure} (the paper's budget)")
    numbers = {"p_iterations": it.p, "lower_iterations": it.lower, "median_a_iterations": it.median_a,
               "median_b_iterations": it.median_b, "evaluations": budget}
    if ev is not None:
        numbers.update({"p_evaluations": ev.p, "lower_evaluations": ev.lower, "median_a_evaluations": ev.median_a,
                        "median_b_evaluations": ev.median_b})
    return Claim(text, verdict(decisive.lower == better), evidence, numbers)


def timing_comparison(exp, a: str, b: str, names: dict[str, str]) -> Comparison | None:
    """Single-run times (ms) of ``a`` and ``b`` (timing_runs.csv), tested like any other sample."""
    if not exp.has("timing_runs.csv"):
        return None
    t = exp.table("timing_runs")
    return compare(names.get(a, a), t[t.algorithm == a].ms.to_numpy(), names.get(b, b),
                   t[t.algorithm == b].ms.to_numpy())


def faster_claim(text: str, faster: str, cmp: Comparison | None) -> Claim:
    """'``faster`` takes less time': held / not held / within noise (rank test on single-run times)."""
    if cmp is None:
        return Claim(text, NOT_CHECKABLE, "no single-run timings stored (timing_runs.csv)")
    lower = cmp.lower
    v = WITHIN_NOISE if lower is None else verdict(lower == faster)
    return Claim(text, v, f"single-run ms per run: {cmp.text()}",
                 {"p": cmp.p, "median_a_ms": cmp.median_a, "median_b_ms": cmp.median_b})


# -- claims.csv and drift --------------------------------------------------------------------------
CLAIMS_FILE = "claims.csv"


def claims_frame(claims: list[Claim]) -> pd.DataFrame:
    return pd.DataFrame([{"claim": c.text, "verdict": c.verdict} for c in claims], columns=["claim", "verdict"])


#: Largest claims.csv read (bytes).
MAX_CLAIMS_BYTES = 4 << 20


def read_claims(file: str | Path) -> dict[str, str]:
    """A stored ``claims.csv`` as {claim: verdict}; a file that is not UTF-8, too large, not a
    CSV or without the ``claim`` and ``verdict`` columns is one line naming it."""
    import io
    from ..errors import FkoptError
    from ..files import read_text
    text = read_text(file, MAX_CLAIMS_BYTES)
    try:
        df = pd.read_csv(io.StringIO(text), dtype=str, keep_default_na=False)
    except (ValueError, pd.errors.ParserError) as err:
        raise FkoptError(f"{file}: not a CSV table ({(str(err).splitlines() or [''])[0][:200]})") from None
    if list(df.columns[:2]) != ["claim", "verdict"]:
        raise FkoptError(f"{file}: expected the columns claim, verdict; got {', '.join(map(str, df.columns[:4]))}")
    return dict(zip(df.claim, df.verdict))


def verdict_changes(root: str | Path) -> list[tuple[str, str, str, str]]:
    """(paper, claim, stored verdict, recomputed verdict) for every claim whose verdict computed
    from the results under ``root`` differs from the stored ``<paper>/claims.csv`` (``(absent)``
    when a claim appeared or disappeared)."""
    from . import paper_module
    from .store import Store
    root = Path(root)
    store = Store(root)
    out = []
    for paper in store.papers():
        mod = paper_module(paper)
        file = root / paper / CLAIMS_FILE
        if mod is None or not file.exists():
            continue
        stored = read_claims(file)
        now = {c.text: c.verdict for c in mod.claims(store)}
        for text in sorted(set(stored) | set(now)):
            a, b = stored.get(text, "(absent)"), now.get(text, "(absent)")
            if a != b:
                out.append((paper, text, a, b))
    return out


def rerun_verdict_drift(exp, rerun_folder: str | Path) -> list:
    """Verdicts of ``exp``'s paper recomputed with the rerun of ``exp`` in place of the stored folder,
    against the stored ``claims.csv`` (``fkopt check``): one :class:`~.check.Mismatch` per change."""
    import shutil
    import tempfile
    from ..compare import Mismatch
    from ..errors import FkoptError
    if not (exp.folder.parent / CLAIMS_FILE).exists():
        return []
    try:
        read_claims(exp.folder.parent / CLAIMS_FILE)
    except FkoptError as err:
        return [Mismatch(f"{exp.paper}/{exp.name}", CLAIMS_FILE, "-", "file", str(err),
                         "a UTF-8 CSV with claim, verdict", "readable")]
    tmp = Path(tempfile.mkdtemp(prefix="fkopt-claims-"))
    try:
        shutil.copytree(exp.folder.parent, tmp / exp.paper)
        shutil.rmtree(tmp / exp.paper / exp.name)
        shutil.copytree(rerun_folder, tmp / exp.paper / exp.name)
        changes = verdict_changes(tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return [Mismatch(f"{exp.paper}/{exp.name}", CLAIMS_FILE, text[:90], "verdict", a, b, "same verdict")
            for _, text, a, b in changes]
