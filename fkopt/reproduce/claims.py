"""Claims of a paper and the verdict vocabulary: the statistics every verdict rests on.

The claims themselves are data (``configs/<paper>/claims.yaml``), judged by the one engine of
:mod:`fkopt.reproduce.engine` (rules in docs/claims.md). This module holds what the engine and the
paper modules share: the :class:`Claim` record, the verdicts, the rank test and the reads of the
stored runs at equal iterations and at equal evaluations, and ``claims.csv`` with its drift
check (``fkopt check``).

Verdicts (:data:`RULES` is printed in the report's preamble):

* **held** / **not held** -- fkopt's numbers support / contradict the claim;
* **conditional: held** / **conditional: not held** -- the same, but judged under a named
  reconstruction or reading of the paper (``claims.csv``'s ``condition`` column names it);
* **not checkable** -- the claim rests on something the paper does not print, or is circular;
* **within noise** -- no significant timing difference (a significant one the other way is *not held*).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from fkopt.algorithms.abc import quality
from fkopt.errors import FkoptError
from fkopt.files import parse_csv, read_text

HELD, NOT_HELD, NOT_CHECKABLE, WITHIN_NOISE = "held", "not held", "not checkable", "within noise"
CONDITIONAL = "conditional: "
VERDICTS = (HELD, NOT_HELD, NOT_CHECKABLE, WITHIN_NOISE, CONDITIONAL + HELD, CONDITIONAL + NOT_HELD,
            CONDITIONAL + WITHIN_NOISE)
ALPHA = 0.05

RULES = [
    "*held* / *not held*: fkopt's numbers support / contradict the claim.",
    "*conditional: held* / *conditional: not held*: the same, judged under a reconstruction or one "
    "reading of an ambiguous equation, named in the claim's *condition*; a claim with several readings "
    "has one row per reading. Every verdict that rests on a reconstruction (the paper's `provenance`: "
    "lost equations, unprinted settings such as a search box, a limit or constants, departures from the "
    "print; a setting is printed only where SPEC.md cites it) is conditional and names it, whichever way "
    "it goes; an absolute time is conditional on fkopt's machine.",
    "*not checkable*: the claim rests on something the paper does not print (lost tables, an error "
    "measure that was lost), or is circular (a model fitted to the very numbers it would confirm); "
    "fkopt's numbers are shown anyway.",
    "*within noise*: no significant timing difference (TIMING.md only); a significant difference the "
    "other way is *not held*.",
    f"A claim that one algorithm beats another is decided by a two-sided Mann-Whitney rank test over "
    f"all runs at alpha = {ALPHA} (p-value shown; identical samples count as no difference), against the "
    "algorithm the paper ran (fkopt's own variants are shown beside it), at equal iterations and at "
    "equal function evaluations (each run read at what the algorithm returns after the budget); the "
    "verdict uses the paper's budget basis and the evidence flags **bases disagree** where the other "
    "basis would reverse it. Where the paper's comparator is underspecified, each candidate "
    "reconstruction has its row.",
    "A magnitude claim uses the mean or the median over all runs (never one run or a maximum over "
    "runs), per coordinate in the paper's units, against the printed order of magnitude "
    "(docs/claims.md).",
]


@dataclass
class Claim:
    text: str          # the paper's claim, in its own terms (with its place: "Fig. 2: ...")
    verdict: str       # one of VERDICTS
    evidence: str      # fkopt's numbers that decide it
    numbers: dict = field(default_factory=dict)   # the numbers behind the verdict (tests, claims.csv)
    id: str = ""       # stable id (claims.yaml; one per reading)
    condition: str = ""   # the reconstruction or reading a conditional verdict rests on
    kind: str = ""

    def __post_init__(self):
        assert self.verdict in VERDICTS, self.verdict


def verdict(ok) -> str:
    return HELD if bool(ok) else NOT_HELD


def missing(text: str, what: str, id: str = "") -> Claim:
    return Claim(text, NOT_CHECKABLE, f"no stored result for {what}", id=id)


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
        if all(v.size and np.isin(v, (0.0, 1.0)).all() for v in (self.values_a, self.values_b)):   # a 0/1 per run
            return (f"{self.a} {int(self.values_a.sum())} of {self.values_a.size} runs vs {self.b} "
                    f"{int(self.values_b.sum())} of {self.values_b.size}, {p_text(self.p)}")
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


def _select(df: pd.DataFrame, algo: str, case: str | None) -> pd.DataFrame:
    return df[df.algorithm == algo] if case is None else df[(df.algorithm == algo) & (df["case"] == case)]


def at_iteration(exp, algo: str, iteration: int | None = None, case: str | None = None) -> np.ndarray:
    """Per-run best-so-far fitness after ``iteration`` (default: the end) from trace.csv.gz/runs.csv."""
    if iteration is None or not exp.has("trace.csv.gz"):
        return _select(exp.table("runs"), algo, case).sort_values(["case", "run"]).final_fitness.to_numpy(float)
    return _from_trace(exp, algo, "iteration", iteration, case)


def at_evaluations(exp, algo: str, evaluations: float, case: str | None = None) -> np.ndarray:
    """Per run, what ``algo`` returns after ``evaluations`` function evaluations.

    A run that spent no more than ``evaluations`` in all returns its final answer (runs.csv's
    ``final_fitness``). A run cut by the budget returns its incumbent then: the trace's
    best-so-far (the lowest fitness evaluated) read through the algorithm's own acceptance rule,
    which for an ABC selecting on Karaboga's quality 1/(1+f) (``selection: karaboga``) keeps an
    improvement only when the quality rises, so it never returns the lower f it could not tell
    apart (:func:`accepted_trace`).
    """
    values = _from_trace(exp, algo, "evaluations", evaluations, case, accepted=True)
    runs = _select(exp.table("runs"), algo, case).sort_values(["case", "run"])
    if len(runs) == values.size and "evaluations" in runs:
        done = runs.evaluations.to_numpy(float) <= evaluations
        values = np.where(done, runs.final_fitness.to_numpy(float), values)
    return values


def selection_of(exp, algo: str) -> str:
    """The greedy selection an algorithm of the experiment used (``params.selection``; raw f by default)."""
    for a in (exp.config or {}).get("algorithms") or []:
        if (a.get("label") or a.get("name")) == algo:
            return str((a.get("params") or {}).get("selection", "raw"))
    return "raw"


def accepted_trace(fitness: np.ndarray, selection: str) -> np.ndarray:
    """The incumbent an algorithm holds after each trace row: the best-so-far itself (raw f), or,
    under Karaboga's quality (``karaboga``), the last value whose quality 1/(1+f) rose."""
    f = np.asarray(fitness, float)
    if selection != "karaboga" or f.size == 0:
        return f
    q = quality(f)
    rose = np.r_[True, q[1:] > np.maximum.accumulate(q)[:-1]]
    idx = np.maximum.accumulate(np.where(rose, np.arange(f.size), 0))
    return f[idx]


def _from_trace(exp, algo, column, budget, case, accepted: bool = False) -> np.ndarray:
    t = _select(exp.table("trace"), algo, case)
    selection = selection_of(exp, algo) if accepted else "raw"
    out = []
    for _, grp in t.groupby(["case", "run"], sort=True):
        held = accepted_trace(grp.best_fitness.to_numpy(float), selection)
        before = (grp[column] <= budget).to_numpy()
        out.append(float(held[before][-1]) if before.any() else float("inf"))
    return np.asarray(out)


def first_below(exp, algo: str, level: float, case: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per run: (iteration, evaluations) at which the best-so-far first went below ``level``
    (inf where it never did), from trace.csv.gz."""
    t = _select(exp.table("trace"), algo, case)
    its, evs = [], []
    for _, grp in t.groupby(["case", "run"], sort=True):
        hit = grp[grp.best_fitness < level]
        its.append(float(hit.iteration.iloc[0]) if len(hit) else np.inf)
        evs.append(float(hit.evaluations.iloc[0]) if len(hit) else np.inf)
    return np.asarray(its), np.asarray(evs)


def within_of_final(exp, algo: str, fraction: float = 0.01) -> tuple[np.ndarray, np.ndarray]:
    """Per run: (iteration, evaluations) at which the best-so-far first came within ``fraction`` of
    the run's own final value (f <= final x (1 + fraction)), from trace.csv.gz."""
    t = _select(exp.table("trace"), algo, None)
    its, evs = [], []
    for _, grp in t.groupby(["case", "run"], sort=True):
        final = float(grp.best_fitness.iloc[-1])
        hit = grp[grp.best_fitness <= final * (1 + fraction)]
        its.append(float(hit.iteration.iloc[0]))
        evs.append(float(hit.evaluations.iloc[0]))
    return np.asarray(its), np.asarray(evs)


def evaluations_at(exp, algo: str, iteration: int | None = None, case: str | None = None) -> float:
    """Evaluations spent after ``iteration`` (or the last recorded one before it): mean over runs
    (convergence.csv); at the end (default) the median over runs (runs.csv)."""
    if iteration is None:
        return float(_select(exp.table("runs"), algo, case).evaluations.median())
    c = exp.table("convergence")
    c = c[(c.algorithm == algo) & (c.iteration <= iteration)]   # a shorter run: its end
    if case is not None:
        c = c[c["case"] == case]
    return float(c.sort_values("iteration").mean_evaluations.iloc[-1])


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


# -- timing ----------------------------------------------------------------------------------------
def timing_comparison(exp, a: str, b: str, names: dict[str, str]) -> Comparison | None:
    """Single-run times (ms) of ``a`` and ``b`` (timing_runs.csv), tested like any other sample."""
    if not exp.has("timing_runs.csv"):
        return None
    t = exp.table("timing_runs")
    return compare(names.get(a, a), t[t.algorithm == a].ms.to_numpy(), names.get(b, b),
                   t[t.algorithm == b].ms.to_numpy())


def resolution(cmp: Comparison) -> float:
    """The relative time difference the sample can separate: the larger relative interquartile
    range of the two timed samples (a shift smaller than the spread is not resolved by n runs)."""
    out = 0.0
    for v in (cmp.values_a, cmp.values_b):
        if v.size:
            q1, q3 = np.percentile(v, [25, 75])
            out = max(out, float((q3 - q1) / max(np.median(v), 1e-300)))
    return out


def faster_claim(text: str, faster: str, cmp: Comparison | None, printed: tuple | None = None) -> Claim:
    """'``faster`` takes less time': held / not held / within noise.

    Rank test on the interleaved single-run times at ALPHA: held when ``faster`` is significantly
    faster, *not held* when it is significantly slower, *within noise* only when the test finds no
    difference. The paper's printed difference (``printed`` = (ms of ``faster``, ms of the other))
    never turns a significant measurement into noise: when it is smaller than the spread of the
    timed runs the evidence says the paper's own numbers do not resolve it, beside the verdict.
    """
    if cmp is None:
        return Claim(text, NOT_CHECKABLE, "no single-run timings stored (timing_runs.csv)")
    res = resolution(cmp)
    lower = cmp.lower
    v = WITHIN_NOISE if lower is None else verdict(lower == faster)
    other = cmp.b if faster == cmp.a else cmp.a
    med = {cmp.a: cmp.median_a, cmp.b: cmp.median_b}
    shift = med[faster] / max(med[other], 1e-300) - 1.0
    size = f"{abs(100 * shift):.1f} %" if abs(shift) < 1 else f"{shift + 1:.1f} x as long,"
    outcome = (f"{faster} {size} {'faster' if shift < 0 else 'slower'} than {other} "
               + ("(no significant difference)" if lower is None else "(significant)"))
    note = ""
    if printed is not None:
        rel = abs(printed[1] - printed[0]) / max(abs(printed[0]), abs(printed[1]))
        if rel < res:
            note = (f"; the paper's printed difference ({100 * rel:.1f} %) is smaller than the run-to-run spread "
                    f"({100 * res:.1f} %): its own numbers do not resolve it")
    n = min(cmp.values_a.size, cmp.values_b.size)
    return Claim(text, v, f"{outcome}: {cmp.text(lambda x: g(x) + ' ms')}; rule: rank test of interleaved single-run ms at alpha = "
                 f"{ALPHA}, n = {n} per algorithm, within noise only without a significant difference (the "
                 f"samples' relative IQR is {100 * res:.1f} %)" + note,
                 {"p": cmp.p, "median_a_ms": cmp.median_a, "median_b_ms": cmp.median_b, "resolution": res,
                  "shift": float(shift)},
                 kind="timing")


# -- claims.csv and drift --------------------------------------------------------------------------
CLAIMS_FILE = "claims.csv"
#: Timing verdicts, stored apart: they change with the machine (``fkopt check`` compares them only
#: where the platform fingerprint matches; :func:`fkopt.reproduce.drift.verdict_changes` with ``timing=True``).
TIMING_CLAIMS_FILE = "timing_claims.csv"
COLUMNS = ["id", "claim", "verdict", "condition"]


def claims_frame(claims: list[Claim]) -> pd.DataFrame:
    return pd.DataFrame([{"id": c.id, "claim": c.text, "verdict": c.verdict, "condition": c.condition}
                         for c in claims], columns=COLUMNS)


def _key(df: pd.DataFrame) -> pd.Series:
    """A claim's key in claims.csv: its id (files written before ids: its text)."""
    if "id" in df and df["id"].notna().all() and (df["id"] != "").all():
        return df["id"].astype(str)
    return df["claim"].astype(str)


#: Largest claims.csv read (bytes).
MAX_CLAIMS_BYTES = 4 << 20


def read_claims(file: str | Path) -> pd.DataFrame:
    """A stored ``claims.csv`` (or ``timing_claims.csv``) as text columns; a file that is not
    UTF-8, too large, not a CSV or without ``claim`` and ``verdict`` columns is one
    :class:`~fkopt.errors.FkoptError` line naming it."""
    text = read_text(file, MAX_CLAIMS_BYTES)
    try:
        df = parse_csv(text.encode("utf-8"), str(file), dtype=str, keep_default_na=False)
    except (ValueError, pd.errors.ParserError) as err:
        raise FkoptError(f"{file}: not a CSV table ({(str(err).splitlines() or [''])[0][:200]})") from None
    if not {"claim", "verdict"} <= set(df.columns):
        raise FkoptError(f"{file}: expected the columns claim and verdict; got {', '.join(map(str, df.columns[:6]))}")
    return df
