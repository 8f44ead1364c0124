"""The one claims engine: every paper's claims, declared in ``configs/<paper>/claims.yaml``, judged by
the same rules (docs/claims.md).

A claims file holds the paper's ``title``, ``experiments`` (report order), ``notes``,
``inconsistencies`` (the paper's internal contradictions, with numbers) and ``claims``. Each claim
has a stable ``id``, the paper's words with their place (``text``), a ``kind`` and the fields of
that kind:

* ``comparison`` -- ``better`` is lower than each of ``than`` (the algorithm(s) the paper ran) in
  ``quantity`` over all runs (rank test, :func:`~.claims.compare`), at equal iterations and at equal
  evaluations; the verdict uses ``basis`` (the paper's, default ``iterations``); ``also`` lists fkopt
  variants shown beside; ``min_orders`` additionally requires a median gain of that many decades;
* ``magnitude`` -- the ``statistic`` (mean or median) over all runs, per coordinate, of ``quantity``
  against the printed order (``order`` +-``decades``, ``order_at_most``, ``below`` or ``above``);
* ``iterations_to_target`` -- the median over all runs of the iteration at which ``algorithm`` first
  went below ``level`` within ``tolerance`` of ``printed``, and (``faster_than``) significantly
  fewer than the other's;
* ``timing`` -- ``faster`` takes less time than ``than`` (interleaved single runs; within noise
  inside the spread; :func:`~.claims.faster_claim`), the times of ``close: [a, b]`` do not differ
  significantly, or every run ``below_ms``; TIMING.md only;
* ``value`` -- a number measured by the paper module (``quantity`` names a function of its
  ``QUANTITIES``), against the same rules as a magnitude.

The paper's ``printed`` table holds the settings SPEC.md cites; its ``provenance`` records every
algorithm, comparator and mechanism with the printed settings it uses and what fkopt ``chose``
beyond them, and is ``printed`` or a ``reconstruction`` by that (:func:`derive_provenance`, never
by hand); :func:`judge` makes every verdict resting on a
reconstruction conditional, naming it, and a reconstruction fitted to a claim (``circular``) makes
that claim not checkable. ``hardware`` names the paper's machine for absolute times; kind
``statement`` is a claim no number decides (``not_checkable`` says why).

Any claim may carry ``condition`` (a reading it rests on: the verdict becomes
``conditional: ...``), ``rests_on`` (parts of ``provenance`` beyond the algorithms it names), ``readings`` (one row per reading, each a ``condition`` and algorithm
replacements ``use: {gabc: gabc_zhu2010}`` and field overrides ``set: {quantity: ...}``) or ``not_checkable`` (why; fkopt's numbers are still
shown). Adding a claim touches the claims file only.
"""
from __future__ import annotations

import os
from functools import lru_cache
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from fkopt.reproduce import paper_module
from fkopt.reproduce.claims import (ALPHA, CONDITIONAL, HELD, NOT_CHECKABLE, NOT_HELD, WITHIN_NOISE, Claim,
                                   at_iteration, compare, equal_budget, faster_claim, first_below, g, missing, p_text,
                                   verdict, within_of_final)

CLAIMS_YAML = "claims.yaml"
#: Where the claims files live: the repository's configs/ (``FKOPT_CONFIGS`` points elsewhere).
CONFIGS = Path(os.environ.get("FKOPT_CONFIGS", Path(__file__).resolve().parents[2] / "configs"))
KINDS = ("comparison", "magnitude", "iterations_to_target", "timing", "value", "statement")


def is_claims_file(path: str | Path) -> bool:
    """A paper's claims file (not an experiment config: ``fkopt reproduce`` skips it)."""
    return Path(path).name == CLAIMS_YAML


@lru_cache(maxsize=None)
def load(paper: str) -> dict | None:
    """The parsed ``configs/<paper>/claims.yaml``, or None."""
    file = CONFIGS / paper / CLAIMS_YAML
    if not file.exists():
        return None
    data = yaml.safe_load(file.read_text(encoding="utf-8")) or {}
    ids = [c["id"] for c in data.get("claims", [])]
    assert len(ids) == len(set(ids)), f"{file}: duplicate claim ids"
    for c in data.get("claims", []):
        assert c.get("kind") in KINDS, f"{file}: {c['id']}: kind {c.get('kind')!r} not in {KINDS}"
    data["provenance"] = derive_provenance(data, file)
    return data


def printed_settings(data: dict) -> dict[str, str]:
    """The paper's printed settings: key -> the words of SPEC.md that cite it (``printed.settings``)."""
    return dict(((data.get("printed") or {}).get("settings") or {}))


def uncited_settings(data: dict, spec_text: str) -> list[str]:
    """The printed settings of a claims file whose words SPEC.md (``spec_text``) does not hold under
    their section (``printed.spec``, or the setting's own ``section``), whitespace aside: each is a
    setting called printed that SPEC.md does not cite."""
    sections, heading = {}, ""
    for line in spec_text.splitlines():
        if line.startswith("## "):
            heading = line[3:].strip()
        sections[heading] = sections.get(heading, "") + " " + line
    flat = {k: " ".join(v.split()) for k, v in sections.items()}
    default = str((data.get("printed") or {}).get("spec") or "")
    out = []
    for key, cite in printed_settings(data).items():
        section, words = (cite.get("section", default), cite.get("words", "")) if isinstance(cite, dict) \
            else (default, cite)
        if " ".join(str(words).split()) not in flat.get(section, "") or not str(words).strip():
            out.append(f"{key}: {section!r} has no {str(words)[:60]!r}")
    return out


def derive_provenance(data: dict, where="claims.yaml") -> dict[str, dict]:
    """Each ``provenance`` entry with its ``as`` derived, never written by hand (issue 41).

    What a paper printed is data: ``printed.settings`` maps a setting to the words of
    /work/shared/SPEC.md that cite it, under the section ``printed.spec``. An entry lists the
    settings it uses (``printed: [keys]``, each one of those) and what fkopt had to choose where
    SPEC.md cites nothing (``chosen``: a search box, a limit, lost equations, a stopping rule, a
    method the paper never ran). It is ``printed`` when it chose nothing and ``reconstruction``
    otherwise, so an unprinted setting makes every verdict resting on it conditional by the one rule.
    """
    settings = printed_settings(data)
    out = {}
    for key, entry in (data.get("provenance") or {}).items():
        entry = dict(entry or {})
        assert "as" not in entry, (f"{where}: provenance {key}: 'as' is derived (printed only where "
                                   "SPEC.md cites every setting: printed.settings), not written by hand")
        cited = _list(entry.get("printed"))
        unknown = [s for s in cited if s not in settings]
        assert not unknown, f"{where}: provenance {key}: {unknown} not in printed.settings ({sorted(settings)})"
        assert cited or entry.get("chosen"), f"{where}: provenance {key}: cites no printed setting and chose nothing"
        entry["as"] = RECONSTRUCTION if str(entry.get("chosen") or "").strip() else PRINTED
        out[key] = entry
    return out


def info(paper: str) -> dict:
    """title, experiments, notes and inconsistencies of a paper (claims.yaml, else the module)."""
    data = load(paper) or {}
    mod = paper_module(paper)
    return {"title": data.get("title") or getattr(mod, "TITLE", paper),
            "experiments": data.get("experiments") or getattr(mod, "EXPERIMENTS", []),
            "notes": (data.get("notes") or getattr(mod, "NOTES", [])),
            "inconsistencies": data.get("inconsistencies") or []}


def judge_paper(paper: str, store, timing_only: bool = False) -> tuple[list[Claim], list[Claim]] | None:
    """(claims, timing claims) of a paper, or None for a folder without claims; ``timing_only``
    judges the timing claims alone (the first list is then empty)."""
    data = load(paper)
    mod = paper_module(paper)
    if data is None:
        if mod is None or not hasattr(mod, "claims"):
            return None
        timing = mod.timing_claims(store) if hasattr(mod, "timing_claims") else []
        return ([] if timing_only else mod.claims(store)), timing
    if not judged_here(paper, store):
        return None
    plain, timing = [], []
    for spec in data.get("claims", []):
        if timing_only and spec["kind"] != "timing":
            continue
        for c in judge(paper, spec, store, mod):
            (timing if spec["kind"] == "timing" else plain).append(c)
    return plain, timing


def claim_experiments(paper: str) -> set[str]:
    """The paper's own experiments its claims are judged on (``experiment``, a reading's ``set``)."""
    out = set()
    for spec in (load(paper) or {}).get("claims", []):
        for reading in spec.get("readings") or [{}]:
            name = str(((reading.get("set") or {}).get("experiment")) or spec.get("experiment") or "")
            if name and "/" not in name:
                out.add(name)
    return out


def judged_here(paper: str, store) -> bool:
    """Are ``paper``'s claims judged in this results tree? Only where it stores at least one of the
    experiments they are judged on: a tree of other runs of the paper's mechanisms (results/peers)
    would give every claim "no stored result", so it gets no verdict files (``fkopt check`` fails on
    one there: :func:`fkopt.reproduce.check.verdict_files`)."""
    names = claim_experiments(paper)
    return not names or any(e.name in names for e in store.experiments(paper))


def judge(paper: str, spec: dict, store, mod=None) -> list[Claim]:
    """One claim of the claims file, judged: one Claim per reading.

    The verdict's condition is the reading's (or the claim's) ``condition`` plus every
    reconstruction the claim rests on (:func:`rests_on`, from the paper's ``provenance``), named,
    whichever way the verdict goes; a part recorded as fitted to this very claim (``circular``)
    makes it *not checkable*; an absolute time limit is judged on fkopt's machine, never the
    paper's, and says so (:data:`HARDWARE_CONDITION`).
    """
    data = load(paper) or {}
    readings = spec.get("readings") or [{"condition": spec.get("condition", "")}]
    out = []
    for k, reading in enumerate(readings):
        cid = spec["id"] if len(readings) == 1 else f"{spec['id']}:{reading.get('id', k + 1)}"
        spec_r = {**spec, **(reading.get("set") or {})}
        use = reading.get("use") or {}
        c = _judge_one(paper, spec_r, use, store, mod, cid)
        c.id, c.kind = cid, spec["kind"]
        parts = rests_on(data, spec_r, use)
        conditions = [reading.get("condition", "") or ""]
        conditions += [f"reconstructed {e.get('name', key)}: {e['chosen'].strip()}" for key, e in parts
                       if e.get("as") == RECONSTRUCTION]
        if spec["kind"] == "timing" and _absolute_time(spec_r):
            conditions.append(HARDWARE_CONDITION.format(hardware=data.get("hardware") or "not printed"))
        c.condition = "; ".join(x.strip() for x in conditions if x and x.strip())
        circular = [(key, e) for key, e in parts if spec["id"] in (e.get("circular") or [])]
        if spec.get("not_checkable"):
            c.evidence = spec["not_checkable"].strip() + (f"; fkopt's numbers: {c.evidence}" if c.evidence else "")
            c.verdict = NOT_CHECKABLE
        elif circular:
            names = " and ".join(e.get("name", key) for key, e in circular)
            c.evidence = (f"circular: the reconstructed {names} was fitted to these very numbers, so agreeing "
                          f"with them confirms nothing; fkopt's numbers: {c.evidence}")
            c.verdict = NOT_CHECKABLE
        elif c.condition and c.verdict in (HELD, NOT_HELD, WITHIN_NOISE):
            c.verdict = CONDITIONAL + c.verdict
        out.append(c)
    return out


RECONSTRUCTION, PRINTED = "reconstruction", "printed"
#: The condition of every absolute time limit (``below_ms``, ``above_ms``): one rule for all papers.
HARDWARE_CONDITION = ("an absolute time, measured on fkopt's machine (TIMING.md's platform), not on the paper's "
                      "({hardware})")
#: The claim fields that name the algorithms a verdict rests on (``also``: shown beside, never judged).
ALGORITHM_FIELDS = ("better", "than", "algorithms", "algorithm", "faster_than", "faster", "close")


def _absolute_time(spec: dict) -> bool:
    return "below_ms" in spec or "above_ms" in spec


def rests_on(data: dict, spec: dict, use: dict | None = None) -> list[tuple[str, dict]]:
    """The parts of the paper's ``provenance`` a claim rests on: (key, entry) pairs.

    The algorithms the verdict compares (:data:`ALGORITHM_FIELDS`, after the reading's ``use``),
    the parts with ``scope: all`` when the claim is judged on a stored experiment (the mechanism
    and the error measure every run used), and the parts the claim lists in ``rests_on`` (claims
    about printed numbers name what they use). A part that is not in ``provenance`` rests on
    nothing recorded (a claims file's test requires every algorithm to be recorded).
    """
    prov = data.get("provenance") or {}
    use = use or {}
    keys = [use.get(a, a) for f in ALGORITHM_FIELDS for a in _list(spec.get(f))]
    if spec.get("experiment"):
        keys += [k for k, e in prov.items() if e.get("scope") == "all"]
    keys += [use.get(a, a) for a in _list(spec.get("rests_on"))]
    return [(k, prov[k]) for k in dict.fromkeys(keys) if k in prov]


def _judge_one(paper, spec, use, store, mod, cid) -> Claim:
    text = spec["text"].strip()
    names = {**((load(paper) or {}).get("names") or {})}
    # ``experiment: other_paper/name`` judges a claim on another paper's stored runs (wu2015's ACO on mao2017's 3-RPS)
    where, _, name = str(spec.get("experiment", "")).rpartition("/")
    exp = store.get(where or paper, name) if spec.get("experiment") else None
    if spec.get("experiment") and exp is None:
        return missing(text, f"{where or paper}/{name}", cid)
    try:
        return KIND_JUDGES[spec["kind"]](text, spec, exp, lambda a: use.get(a, a), names, store, mod)
    except _Missing as err:
        return missing(text, str(err), cid)


class _Missing(Exception):
    """A result the claim needs is not stored (an older results tree): not checkable."""


# -- per-run quantities ------------------------------------------------------------------------
def runs_table(exp, mod) -> pd.DataFrame:
    """runs.csv plus the per-run columns the experiment's own paper module derives (``run_columns``;
    a claim judged on another paper's experiment gets that paper's columns)."""
    runs = exp.table("runs")
    if getattr(exp, "paper", None) and paper_module(exp.paper) is not None:
        mod = paper_module(exp.paper)
    extra = getattr(mod, "run_columns", None)
    return extra(exp, runs) if extra else runs


def per_run(exp, mod, algo: str, quantity: str, spec: dict) -> tuple[np.ndarray, np.ndarray | None]:
    """(values, values on the evaluation basis or None) of ``quantity`` per run of ``algo``, all runs.

    ``final_fitness`` (at ``spec['iteration']``, default the end), ``iterations_to_threshold``,
    ``first_below`` (``spec['level']``) and ``within_1pct_of_final`` come with their evaluation
    twin; ``log10_change`` is log10 f at the end of ``spec['window']`` minus at its start
    (negative is progress); any other name is a per-run column (runs.csv or ``run_columns``), final values only.
    """
    runs = runs_table(exp, mod)
    if algo not in set(runs.algorithm):
        raise _Missing(f"{exp.paper}/{exp.name}: algorithm {algo}")
    r = runs[runs.algorithm == algo].sort_values(["case", "run"])
    if quantity == "iterations_to_threshold":
        return (r.iterations_to_threshold.fillna(np.inf).to_numpy(float),
                r.evaluations_to_threshold.fillna(np.inf).to_numpy(float))
    if quantity in ("first_below", "within_1pct_of_final", "log10_change") and not exp.has("trace.csv.gz"):
        raise _Missing(f"{exp.paper}/{exp.name}/trace.csv.gz")
    if quantity == "first_below":
        return first_below(exp, algo, float(spec["level"]))
    if quantity == "within_1pct_of_final":
        return within_of_final(exp, algo, 0.01)
    if quantity == "log10_change":
        a, b = spec["window"]
        f0, f1 = at_iteration(exp, algo, a), at_iteration(exp, algo, b)
        return np.log10(np.maximum(f1, 1e-300)) - np.log10(np.maximum(f0, 1e-300)), None
    if quantity.startswith("spread:"):   # run-to-run stability: each run's |value - the median run's|
        base = quantity.removeprefix("spread:")
        if base not in r:
            raise _Missing(f"{exp.paper}/{exp.name}: per-run {base}")
        v = r[base].to_numpy(float)
        return np.abs(v - np.median(v)), None
    if quantity not in r:
        raise _Missing(f"{exp.paper}/{exp.name}: per-run {quantity}")
    return r[quantity].to_numpy(float), None


#: final per-run values that the trace does not hold, judged at equal evaluations through the objective
TRACED_PROXY = ("position_error",)


# -- kinds ---------------------------------------------------------------------------------------
def _comparison(text, spec, exp, use, names, store, mod) -> Claim:
    better = use(spec["better"])
    than = [use(a) for a in _list(spec["than"])]
    quantity = spec.get("quantity", "final_fitness")
    basis = spec.get("basis", "iterations")
    nm = lambda a: names.get(a, a)   # noqa: E731
    parts, numbers, held = [], {}, {"iterations": True, "evaluations": True}
    # a final per-run value that is not traced (position error): the bases are compared on the objective f
    # at both, like with like (issue 41), while the verdict stays on the quantity at the paper's basis
    proxy_iterations = None
    for other in than + [use(a) for a in _list(spec.get("also"))]:
        beside = other not in than
        it_f = None
        if quantity == "final_fitness":
            it, ev, budget = equal_budget(exp, better, other, names, iteration=spec.get("iteration"))
            ev_label = f"equal evaluations ({budget:.0f})"
        else:
            va, va_ev = per_run(exp, mod, better, quantity, spec)
            vb, vb_ev = per_run(exp, mod, other, quantity, spec)
            it = compare(nm(better), va, nm(other), vb)
            ev = compare(nm(better), va_ev, nm(other), vb_ev) if va_ev is not None else None
            ev_label = "in evaluations"
            if ev is None and quantity in TRACED_PROXY and exp.has("trace.csv.gz"):
                # a final per-run value (e.g. position error) is not traced: the objective stands in, at
                # equal evaluations and (to compare the bases like with like) at equal iterations
                it_f, ev, budget = equal_budget(exp, better, other, names)
                ev_label = (f"the objective f ({quantity} is not traced) at equal iterations: {it_f.text()}; "
                            f"f at equal evaluations ({budget:.0f})")
        tag = f"{nm(better)} vs {nm(other)}" + (" (fkopt's variant, beside)" if beside else "")
        ev_text = ev.text() if ev is not None else "n/a (a final per-run value; not in the trace)"
        parts.append(f"{tag}: equal iterations: {it.text()}; {ev_label}: {ev_text}")
        key = other if not beside else f"{other}_beside"
        numbers.update({f"p_{key}": it.p, f"lower_{key}": it.lower, f"median_{better}": it.median_a,
                        f"median_{other}": it.median_b})
        if ev is not None:
            numbers.update({f"p_evaluations_{key}": ev.p, f"lower_evaluations_{key}": ev.lower})
        if it_f is not None:
            numbers.update({f"p_f_iterations_{key}": it_f.p, f"lower_f_iterations_{key}": it_f.lower})
        if beside:
            continue
        if it_f is not None:
            proxy_iterations = (True if proxy_iterations is None else proxy_iterations) and it_f.lower == nm(better)
        held["iterations"] &= it.lower == nm(better)
        held["evaluations"] = held["evaluations"] and (ev.lower == nm(better) if ev is not None else None)
        if spec.get("min_orders") is not None:
            gain = np.log10(max(it.median_b, 1e-300)) - np.log10(max(it.median_a, 1e-300))
            numbers[f"orders_{other}"] = float(gain)
            parts[-1] += f"; median gain {gain:.1f} decades (the claim needs >= {spec['min_orders']})"
            held["iterations"] &= gain >= spec["min_orders"]
            if ev is not None:
                gain_ev = np.log10(max(ev.median_b, 1e-300)) - np.log10(max(ev.median_a, 1e-300))
                numbers[f"orders_evaluations_{other}"] = float(gain_ev)
                parts[-1] += f" (at equal evaluations {gain_ev:.1f})"
                held["evaluations"] = held["evaluations"] and gain_ev >= spec["min_orders"]
    decisive = held[basis] if held[basis] is not None else held["iterations"]
    other_basis = "evaluations" if basis == "iterations" else "iterations"
    note = ""
    if proxy_iterations is not None:
        # the bases on the objective f, like with like: f at equal iterations against f at equal evaluations
        if held["evaluations"] is not None and bool(held["evaluations"]) != bool(proxy_iterations):
            note = (f"; **bases disagree** on the objective f: at equal iterations {verdict(proxy_iterations)}, at "
                    f"equal evaluations {verdict(held['evaluations'])}")
            numbers["bases_disagree"] = True
    elif held[other_basis] is not None and bool(held[other_basis]) != bool(decisive):
        note = f"; **bases disagree**: at equal {other_basis} the verdict would be {verdict(held[other_basis])}"
        numbers["bases_disagree"] = True
    on_basis = {o: numbers.get(f"lower_{o}" if basis == "iterations" else f"lower_evaluations_{o}",
                               numbers.get(f"lower_{o}")) for o in than}
    relation = lambda low: ("significantly lower than" if low == nm(better) else   # noqa: E731
                            "not significantly different from" if low is None else "significantly higher than")
    words = [f"{relation(low)} {nm(o)}" for o, low in on_basis.items()]
    outcome = f"{nm(better)} is {' and '.join(words)} at equal {basis}"
    if spec.get("min_orders") is not None:
        lower_everywhere = all(low == nm(better) for low in on_basis.values())
        outcome += (f" (the claim also needs >= {spec['min_orders']} decades: "
                    f"{'reached' if decisive else 'not reached' if lower_everywhere else 'moot'})")
    rule = (f"rule: two-sided rank test over all runs at alpha = {ALPHA} on the paper's basis (equal {basis})"
            + (f", and a median gain of >= {spec['min_orders']} decades" if spec.get("min_orders") is not None else ""))
    return Claim(text, verdict(decisive), f"{outcome}: " + "; ".join(parts) + f"; {rule}" + note, numbers)


RULE_FIELDS = ("order", "order_at_most", "below", "above", "at_least", "equals")


def _rule(value: float, spec: dict, algo: str | None = None) -> tuple[bool, str, str]:
    """(held, outcome, rule) of a number against the claim's magnitude rule: the outcome says what
    was measured against the printed number ("+1.2 decades from the printed 1e-20, outside"), the
    rule states the test ("within +-0.5 decades of the printed order"). A rule's number may be a
    mapping per algorithm, e.g. the printed mean of each."""
    per_algo = any(isinstance(spec.get(k), dict) for k in RULE_FIELDS)
    spec = {k: (v.get(algo) if isinstance(v, dict) and k in RULE_FIELDS else v) for k, v in spec.items()}
    each = "each algorithm's printed " if per_algo else ""
    if spec.get("order") is not None:
        d = float(spec.get("decades", 0.5))
        off = np.log10(max(value, 1e-300)) - np.log10(spec["order"])
        ok = abs(off) <= d
        return ok, f"{off:+.2f} decades from the printed {g(spec['order'])}, {'within' if ok else 'outside'} +-{d:g}", \
            f"within +-{d:g} decades of {each or 'the printed '}order"
    if spec.get("order_at_most") is not None:
        cap = 10.0 ** (np.floor(np.log10(spec["order_at_most"])) + 1)
        ok = value < cap
        return ok, f"{'below' if ok else 'not below'} {g(cap)}", \
            f"of {each or 'the printed '}order ({g(spec['order_at_most'])}) or below, i.e. below the next decade"
    for key, word in (("below", "below"), ("above", "above"), ("at_least", "at least"), ("equals", "equal to")):
        if spec.get(key) is not None:
            x = spec[key]
            ok = {"below": value < x, "above": value > x, "at_least": value >= x, "equals": value == x}[key]
            return ok, f"{'' if ok else 'not '}{word} {g(x)}", f"{word} {g(x) if not per_algo else each + 'value'}"
    raise ValueError(f"no rule in {spec}")


def _magnitude(text, spec, exp, use, names, store, mod) -> Claim:
    stat = spec.get("statistic", "median")
    assert stat in ("mean", "median"), "magnitude claims use the mean or the median over all runs"
    fn = np.mean if stat == "mean" else np.median
    runs = runs_table(exp, mod)
    if spec.get("case") is not None:   # a claim about one of the experiment's cases
        runs = runs[runs["case"] == spec["case"]]
    quantity = spec.get("quantity", "final_fitness")
    units = {}
    if exp.has("values.csv") and "unit" in exp.table("values"):
        v = exp.table("values")
        units = dict(zip(v.variable, v.unit))
    parts, numbers, ok = [], {}, True
    for algo in [use(a) for a in _list(spec["algorithms"])]:
        if algo not in set(runs.algorithm):
            raise _Missing(f"{exp.paper}/{exp.name}: algorithm {algo}")
        if isinstance(quantity, list):   # some coordinates (e.g. the position's)
            cols = quantity
        elif quantity == "abs_error":   # per coordinate, the paper's units
            cols = [c for c in runs.columns if c.startswith("abs_error_")]
        elif quantity in runs:
            cols = [quantity]
        else:
            cols = None
        groups = runs[runs.algorithm == algo].groupby("case", sort=False) if spec.get("per_case") else \
            [("all", runs[runs.algorithm == algo])]
        for case, grp in groups:
            if cols is None:
                values = {quantity: per_run(exp, mod, algo, quantity, spec)[0]}
            else:
                values = {c: grp[c].to_numpy(float) for c in cols}
            for col, vals in values.items():
                s = float(fn(vals))
                good, outcome, rule = _rule(s, spec, algo)
                ok &= good
                var = col.removeprefix("abs_error_")
                label = f"{names.get(algo, algo)}{'' if case == 'all' else ' ' + str(case)} {var}"
                parts.append(f"{label} {g(s)}{' ' + units[var] if var in units else ''} ({outcome})")
                numbers[f"{stat}_{algo}_{var}" + ("" if case == "all" else f"_{case}")] = s
    return Claim(text, verdict(ok), f"{stat} over all runs, per coordinate: {', '.join(parts)}; rule: the {stat} of "
                 f"each {rule}", numbers)


def _iterations_to_target(text, spec, exp, use, names, store, mod) -> Claim:
    algo = use(spec["algorithm"])
    q = "first_below" if "level" in spec else "iterations_to_threshold"
    its, evs = per_run(exp, mod, algo, q, spec)
    med = float(np.median(its))
    tol = float(spec.get("tolerance", 0.25))
    ok = abs(med - spec["printed"]) <= tol * spec["printed"]
    level = spec.get("level", exp.config.get("threshold"))
    off = (med - spec["printed"]) / spec["printed"]
    ev = (f"median over all {its.size} runs of the iteration at which {names.get(algo, algo)} first went below "
          f"{g(level)}: {g(med)} ({g(float(np.median(evs)))} evaluations; {int(np.isinf(its).sum())} runs never), "
          f"{abs(100 * off):.0f} % {'above' if off > 0 else 'below'} the printed {g(spec['printed'])}, "
          f"{'within' if abs(off) <= tol else 'outside'} {tol:.0%}")
    numbers = {f"median_iterations_{algo}": med}
    if spec.get("faster_than"):
        other = use(spec["faster_than"])
        o_its, o_evs = per_run(exp, mod, other, q, spec)
        ci = compare(names.get(algo, algo), its, names.get(other, other), o_its)
        ce = compare(names.get(algo, algo), evs, names.get(other, other), o_evs)
        ok = ok and ci.lower == names.get(algo, algo)
        ev += f"; vs {names.get(other, other)}: iterations {ci.text()}; evaluations {ce.text()}"
        numbers.update({f"median_iterations_{other}": ci.median_b, "p_iterations": ci.p, "lower_iterations": ci.lower,
                        "p_evaluations": ce.p, "lower_evaluations": ce.lower})
        if (ce.lower == names.get(algo, algo)) != (ci.lower == names.get(algo, algo)):
            ev += "; **bases disagree**"
            numbers["bases_disagree"] = True
    ev += f"; rule: the median within +-{tol:.0%} of the printed count" + (
        f" and significantly fewer iterations than {names.get(spec['faster_than'], spec['faster_than'])}"
        if spec.get("faster_than") else "")
    return Claim(text, verdict(ok), ev, numbers)


def _timing(text, spec, exp, use, names, store, mod) -> Claim:
    if not exp.has("timing_runs.csv"):
        return Claim(text, NOT_CHECKABLE, "no single-run timings stored (timing_runs.csv)")
    t = exp.table("timing_runs")
    if "below_ms" in spec or "above_ms" in spec:
        return _time_limit(text, spec, t, use, names)
    a, b = (use(x) for x in _list(spec["close"])) if spec.get("close") else (use(spec["faster"]), use(spec["than"]))
    ms = {x: t[t.algorithm == x].ms.to_numpy(float) for x in (a, b)}
    if not all(v.size for v in ms.values()):
        raise _Missing(f"{exp.paper}/{exp.name}/timing_runs.csv: timed runs of {a} and {b}")
    if spec.get("time_to_best"):
        return _time_to_best(text, spec, exp, mod, a, b, ms, names)
    cmp = compare(names.get(a, a), ms[a], names.get(b, b), ms[b])
    if spec.get("close"):
        return _close(text, cmp)
    c = faster_claim(text, names.get(a, a), cmp, tuple(spec["printed_ms"]) if "printed_ms" in spec else None)
    if "saving" in spec and c.verdict == "held":
        saving = 1.0 - cmp.median_a / cmp.median_b
        c.numbers["saving"] = float(saving)
        c.verdict = verdict(abs(saving - spec["saving"]) <= 0.1)
        c.evidence = (f"{100 * saving:.1f} % shorter, {'within' if c.verdict == HELD else 'more than'} 10 points of "
                      f"the printed {100 * spec['saving']:.2f} % (rule: within 10 points); " + c.evidence)
    return c


def _close(text, cmp) -> Claim:
    """'the times of ``a`` and ``b`` are close' (``close: [a, b]``), by the one timing rule: the rank
    test of the interleaved single-run times at ALPHA (:func:`~.claims.faster_claim`) decides; held when
    it finds no significant difference, not held when it finds one, either way."""
    c = faster_claim(text, cmp.a, cmp)
    shifted = c.verdict != WITHIN_NOISE
    c.verdict = verdict(not shifted)
    c.evidence = ("significantly different, so not close: " if shifted else "no significant difference: ") + \
        c.evidence.replace("within noise only without a significant difference",
                           "close (held) only without a significant difference")
    return c


def _time_limit(text, spec, t, use, names) -> Claim:
    """Every timed run below ``below_ms`` (a claim about every run: the slowest decides), or the
    median timed run above ``above_ms`` (an algorithm too slow for a limit)."""
    algos = [use(a) for a in _list(spec["algorithms"])]
    ms = t[t.algorithm.isin(algos)].ms.to_numpy(float)
    if not ms.size:
        raise _Missing(f"timed runs of {', '.join(algos)}")
    who = ", ".join(names.get(a, a) for a in algos)
    if "below_ms" in spec:
        worst = float(ms.max())
        ok = worst < spec["below_ms"]
        return Claim(text, verdict(ok), f"slowest of the {ms.size} timed single runs of {who}: {g(worst)} ms, "
                     f"{'below' if ok else 'not below'} {g(spec['below_ms'])} ms (rule: every run below the limit, "
                     "so the slowest decides)", {"worst_ms": worst})
    med = float(np.median(ms))
    ok = med > spec["above_ms"]
    return Claim(text, verdict(ok), f"median of the {ms.size} timed single runs of {who}: {g(med)} ms, "
                 f"{'above' if ok else 'not above'} {g(spec['above_ms'])} ms (rule: the median run above the limit)",
                 {"median_ms": med})


def _time_to_best(text, spec, exp, mod, a, b, ms, names) -> Claim:
    """'``a`` finds its best in less time than ``b``' over ALL runs, not the timed ones: each run's
    iterations to its best (runs.csv, every run) times its algorithm's median time per iteration
    (the timed single runs, interleaved), rank-tested; both factors are tested and shown."""
    runs = runs_table(exp, mod)
    per_it = {x: float(np.median(ms[x])) / float(exp.config["iterations"]) for x in (a, b)}
    its = {x: runs[runs.algorithm == x].sort_values(["case", "run"]).iterations_to_best.to_numpy(float) for x in (a, b)}
    if not all(v.size for v in its.values()):
        raise _Missing(f"{exp.paper}/{exp.name}: runs of {a} and {b}")
    nm = lambda x: names.get(x, x)   # noqa: E731
    tbest = compare(nm(a), its[a] * per_it[a], nm(b), its[b] * per_it[b])
    it_cmp = compare(nm(a), its[a], nm(b), its[b])
    run_cmp = compare(nm(a), ms[a], nm(b), ms[b])
    lower = tbest.lower
    v = WITHIN_NOISE if lower is None else verdict(lower == nm(a))
    outcome = (f"time to best over all {tbest.values_a.size} vs {tbest.values_b.size} runs: median {nm(a)} "
               f"{g(tbest.median_a)} ms vs {nm(b)} {g(tbest.median_b)} ms, {p_text(tbest.p)}")
    return Claim(text, v, f"{outcome}; iterations to best (every run): {it_cmp.text()}; a whole "
                 f"{exp.config['iterations']}-iteration run (timed runs): {run_cmp.text(lambda x: g(x) + ' ms')}; "
                 "rule: "
                 "each run's iterations to best x its algorithm's median ms per iteration, rank test at alpha = "
                 f"{ALPHA} over all runs, within noise only without a significant difference",
                 {"p": tbest.p, "median_a_ms": tbest.median_a, "median_b_ms": tbest.median_b,
                  "p_iterations": it_cmp.p, "lower_iterations": it_cmp.lower, "p_run_ms": run_cmp.p,
                  "lower_run_ms": run_cmp.lower}, kind="timing")


def _value(text, spec, exp, use, names, store, mod) -> Claim:
    fn = (getattr(mod, "QUANTITIES", {}) or {}).get(spec["quantity"])
    assert fn is not None, f"{spec['id']}: the paper module has no quantity {spec['quantity']!r}"
    got = fn(store)
    if got is None:
        raise _Missing(f"the results behind {spec['quantity']}")
    value, evidence, numbers = got
    ok, outcome, rule = _rule(value, spec)
    return Claim(text, verdict(ok), f"{spec['quantity']} = {g(value)}, {outcome}: {evidence}; rule: {rule}", numbers)


def _statement(text, spec, exp, use, names, store, mod) -> Claim:
    """A claim no stored number can decide: its row says why (``not_checkable``)."""
    assert spec.get("not_checkable"), f"{spec['id']}: a statement is judged not checkable and says why"
    return Claim(text, NOT_CHECKABLE, "")


KIND_JUDGES = {"statement": _statement, "comparison": _comparison, "magnitude": _magnitude,
               "iterations_to_target": _iterations_to_target,
               "timing": _timing, "value": _value}


def _list(x) -> list:
    return [] if x is None else list(x) if isinstance(x, (list, tuple)) else [x]


__all__ = ["ALPHA", "judge_paper", "judge", "load", "info", "is_claims_file", "p_text"]
