"""The pieces of a suite's pages (put together by :mod:`fkopt.kinbench.pages`): static HTML --
sortable tables (a few lines of inline JavaScript: a click on a header sorts by that column,
again reverses), headers in words with units, figures as the PNG files beside the page
(relative links, loaded lazily below the first screen). Nothing is loaded from the network."""
from __future__ import annotations

import html
import re
from pathlib import Path

import numpy as np

from fkopt.files import png_size

SCRIPT = """
function sortTable(th) {
  var table = th.closest('table'), body = table.tBodies[0];
  var col = Array.prototype.indexOf.call(th.parentNode.children, th);
  var asc = th.getAttribute('data-dir') !== 'asc';
  Array.prototype.forEach.call(th.parentNode.children, function (h) { h.removeAttribute('data-dir'); });
  th.setAttribute('data-dir', asc ? 'asc' : 'desc');
  var rows = Array.prototype.slice.call(body.rows);
  rows.sort(function (a, b) {
    var x = a.cells[col].getAttribute('data-v'), y = b.cells[col].getAttribute('data-v');
    if (x === null) { x = a.cells[col].textContent; } if (y === null) { y = b.cells[col].textContent; }
    var nx = parseFloat(x), ny = parseFloat(y), r;
    if (!isNaN(nx) && !isNaN(ny)) { r = nx - ny; } else { r = x < y ? -1 : (x > y ? 1 : 0); }
    return asc ? r : -r;
  });
  rows.forEach(function (r) { body.appendChild(r); });
}
document.addEventListener('click', function (e) {
  var th = e.target.closest('th');
  if (th && th.closest('table.sortable')) { sortTable(th); }
});
"""

STYLE = """
body { font-family: sans-serif; margin: 0.8em 1.2em; max-width: 84em; line-height: 1.3; }
h1 { font-size: 1.35em; margin: 0.2em 0; } h2 { font-size: 1.1em; margin: 0.7em 0 0.3em; }
h3 { font-size: 1em; margin: 0.6em 0 0.2em; } p { margin: 0.3em 0; }
nav.toc { font-size: 0.85em; margin: 0.2em 0 0.4em; } nav.toc a { margin-right: 0.9em; white-space: nowrap; }
table { border-collapse: collapse; margin: 0.3em 0 0.8em; font-size: 0.8em; }
th, td { border: 1px solid #ccc; padding: 0.1em 0.4em; text-align: right; }
th { background: #eee; cursor: pointer; font-weight: normal; vertical-align: bottom; max-width: 11em; min-width: 4em;
     font-size: 0.95em; line-height: 1.15; }
th[data-dir=asc]::after { content: " \\25B2"; } th[data-dir=desc]::after { content: " \\25BC"; }
td.t { text-align: left; white-space: nowrap; } td.w { text-align: left; white-space: normal; max-width: 60em; }
.lead { display: grid; grid-template-columns: minmax(0, auto) minmax(18em, 25em); gap: 1.2em; align-items: start; }
.lead > div { min-width: 0; overflow-x: auto; } .lead > figure { margin: 0; }
figure { margin: 0.3em 0; display: inline-block; max-width: 100%; } figure img { width: 100%; max-width: 42em; height: auto; }
figcaption { font-size: 0.8em; color: #444; } .figs figure { width: 32em; margin-right: 0.6em; }
span.n { white-space: nowrap; } details { margin: 0.2em 0; } summary { cursor: pointer; } .note { font-size: 0.85em; color: #444; }
"""

#: CSV columns -> page header (words, units); a column not named here falls back to :func:`words`.
WORDS = {
    "solver": "solver", "robot": "arm", "family": "arm family", "class": "problem class", "problem": "problem",
    "board": "board", "track": "track", "entry": "entry", "arms": "arms", "problems": "problems",
    "timeout_ms": "timeout (ms)", "queries": "queries",
    "time_ms_median": "median time to an answer (ms)", "time_ms_p95": "95th-percentile time to an answer (ms)",
    "time_ratio_median": "median time ratio to the reference", "time_ratio_p95": "95th-percentile time ratio to the reference",
    "cpu_ms_median": "median CPU time per call (ms)", "cpu_ms_p95": "95th-percentile CPU time per call (ms)",
    "reference": "reference solver", "reference_ms_median": "reference's median time (ms)",
    "throughput_qps": "throughput at the largest batch (queries/s)", "throughput_batch": "largest batch (queries)",
    "throughput_ratio": "throughput ratio to the reference", "other_mode": "answers in another assembly mode (%)",
    "worst_arm": "worst arm's success at the board's rung (%)", "median_ms": "median time to an answer (ms)",
    "median_ratio": "median time ratio to rtb ik_LM (one query, same machine)",
    "rank": "rank", "score": "score (ECDF area, 0 to 1)", "ci_low": "95 % CI, low", "ci_high": "95 % CI, high",
    "instances": "instances (problem, set, pose)", "better_than": "better than (Wilcoxon, Holm, 5 %)",
    "set": "pose set", "target": "fitness target", "trials": "runs", "success_rate": "success (%)",
    "ert": "ERT (evaluations)", "ert_per_dim": "ERT per unknown (evaluations)", "dim": "unknowns",
    "ms_per_solve": "median time per solve (ms)", "source": "source", "rung": "board's rung",
}
#: Columns shown in per cent (the CSVs keep shares 0..1).
PERCENT = re.compile(r"^(success_.*|success_rate|other_mode)$")


def number(text: str) -> str:
    """A CSV label's number as a reader writes it: ``1e-05`` -> ``1e-5``, ``1e+00`` -> ``1``,
    ``0.05`` stays."""
    text = str(text)
    try:
        v = float(text)
    except ValueError:
        return text
    if "e" in text.lower():
        mantissa, exponent = text.lower().split("e")
        return mantissa if int(exponent) == 0 else f"{mantissa}e{int(exponent)}"
    return f"{v:g}"


def rung_words(label: str) -> str:
    """``1e-05m_1e-05rad`` -> ``1e-5 m and 1e-5 rad``; ``5mm_0.05rad`` -> ``5 mm and 0.05 rad``;
    a fitness target ``1e-06`` -> ``fitness 1e-6``."""
    m = re.fullmatch(r"([0-9.e+-]+?)(mm|m)_([0-9.e+-]+)rad", label)
    if m:
        return f"{number(m[1])} {m[2]} and {number(m[3])} rad"
    return f"fitness {number(label)}"


def words(col: str, reference: str | None = None) -> str:
    """The page header of CSV column ``col`` (the CSV keeps its name): words with units."""
    if col.startswith("success_") and col != "success_rate":
        return f"success at {rung_words(col[len('success_'):])} (%)"
    if col.startswith("ert_ratio_"):
        return f"ERT ratio to the virtual best at {rung_words(col[len('ert_ratio_'):])}"
    text = WORDS.get(col)
    if text is None:         # a column this page does not know yet (a newer board): its name, unit apart
        text = col.replace("_", " ")
        for suffix, unit in (("_ms", "ms"), ("_s", "s"), ("_qps", "queries/s"), ("_m", "m"), ("_rad", "rad")):
            if col.endswith(suffix):
                text = f"{col[: -len(suffix)].replace('_', ' ')} ({unit})"
                break
    if reference and "to the reference" in text:
        text = text.replace("to the reference", f"to {reference}")
    return text


def _cell(v, percent: bool = False, scale: float = 1.0) -> str:
    if isinstance(v, (bool, np.bool_)):
        return f'<td class="t">{"yes" if v else "no"}</td>'
    if percent and isinstance(v, (int, np.integer)):
        v = float(v)          # a share column read back from a CSV of whole numbers (0 and 1) is int
    if isinstance(v, (float, np.floating)):
        v = float(v) * scale
        if np.isnan(v):
            return '<td data-v=""></td>'
        shown = ("inf" if np.isinf(v) else f"{v:.1f}".removesuffix(".0") if percent
                 else f"{v:.0f}" if abs(v) >= 1e4 else f"{v:.4g}")
        key = "1e308" if np.isinf(v) else f"{v:.6g}"
        return f'<td data-v="{key}">{shown}</td>' if key != shown else f"<td>{shown}</td>"
    if isinstance(v, (int, np.integer)):
        return f"<td>{int(v)}</td>"
    text = html.escape(str(v))
    return f'<td class="{"w" if len(text) > 60 else "t"}">{text}</td>'


def _unbroken(text: str) -> str:
    """Escaped header text whose numbers (1e-5) never break at their minus sign."""
    return re.sub(r"(\d[\d.]*e[-+]?\d+)", r'<span class="n">\1</span>', html.escape(text))


def table_html(df, cols: list[str], ident: str, reference: str | None = None, labels: dict | None = None,
               shares: bool = True) -> str:
    """A sortable table of ``df[cols]``; headers in words (:func:`words`, or ``labels``), the CSV's
    column name in each header's tooltip; shares (success) shown in per cent (``shares=False``:
    the table holds per cent already, as :mod:`fkopt.kinbench.advice`'s summaries)."""
    labels = labels or {}
    head = "".join(f'<th title="{html.escape(c)}">{_unbroken(labels.get(c) or words(c, reference))}</th>'
                   for c in cols)
    pct = [bool(PERCENT.match(c)) or (not shares and c == "worst_arm") for c in cols]
    scale = [100.0 if p and shares else 1.0 for p in pct]
    body = "".join("<tr>" + "".join(_cell(v, p, k) for v, p, k in zip(row, pct, scale)) + "</tr>"
                   for row in df[cols].itertuples(index=False))
    return (f'<table class="sortable" id="{html.escape(ident)}"><thead><tr>{head}</tr></thead>'
            f"<tbody>{body}</tbody></table>")


def _figure_size(path: Path) -> tuple[int, int] | None:
    """The pixel size of the PNG at ``path`` (a figure fkopt drew), or None."""
    try:
        with open(path, "rb") as f:
            return png_size(f.read(24))
    except OSError:
        return None


def img(path: Path, caption: str | None = None, lazy: bool = True) -> str:
    """A figure: the PNG beside the page, by its relative name (never inlined: a page stays small).
    Its pixel size is on the ``img``, so the browser reserves the figure's height before a lazy
    figure loads: without it, a figure that loaded after a jump from the contents moved the section
    out of view (a CI check on a loaded machine: 322 px)."""
    name = html.escape(Path(path).name)
    cap = f"<figcaption>{html.escape(caption)}</figcaption>" if caption else ""
    loading = ' loading="lazy"' if lazy else ""
    size = _figure_size(path)
    dims = f' width="{size[0]}" height="{size[1]}"' if size else ""
    return (f'<figure><a href="{name}"><img alt="{html.escape(Path(path).stem)}" src="{name}"{dims}{loading}></a>'
            f"{cap}</figure>")


def toc(entries: list[tuple[str, str]]) -> str:
    """The table of contents: in-page links (#id, title)."""
    links = " ".join(f'<a href="#{html.escape(i)}">{html.escape(t)}</a>' for i, t in entries)
    return f'<nav class="toc" id="toc"><b>Contents:</b> {links}</nav>'


def page(title: str, body: list[str]) -> str:
    return ("<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
            f"<title>{html.escape(title)}</title><style>{STYLE}</style></head><body>"
            + "\n".join(body) + f"<script>{SCRIPT}</script></body></html>\n")
