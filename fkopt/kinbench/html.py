"""index.html: one self-contained static page -- the leaderboards as sortable tables (a few lines
of inline JavaScript: a click on a header sorts by that column, again reverses), the ECDF figures
inline as ``data:`` URIs, the per-problem tables. Nothing is loaded from the network."""
from __future__ import annotations

import base64
import html
from pathlib import Path

import numpy as np

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
    var nx = parseFloat(x), ny = parseFloat(y), r;
    if (!isNaN(nx) && !isNaN(ny)) { r = nx - ny; } else { r = x < y ? -1 : (x > y ? 1 : 0); }
    return asc ? r : -r;
  });
  rows.forEach(function (r) { body.appendChild(r); });
}
document.addEventListener('click', function (e) {
  if (e.target.tagName === 'TH' && e.target.closest('table.sortable')) { sortTable(e.target); }
});
"""

STYLE = """
body { font-family: sans-serif; margin: 2em; max-width: 70em; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.2em 0.5em; text-align: right; }
th { background: #eee; cursor: pointer; }
th[data-dir=asc]::after { content: " \\25B2"; } th[data-dir=desc]::after { content: " \\25BC"; }
td.t { text-align: left; } img { max-width: 100%; }
"""


def _cell(v) -> str:
    if isinstance(v, (float, np.floating)):
        v = float(v)
        shown = "inf" if np.isinf(v) else ("" if np.isnan(v) else f"{v:.4g}")
        key = "1e308" if np.isinf(v) else ("" if np.isnan(v) else repr(v))
        return f'<td data-v="{key}">{shown}</td>'
    if isinstance(v, (int, np.integer)):
        return f'<td data-v="{int(v)}">{int(v)}</td>'
    return f'<td class="t" data-v="{html.escape(str(v))}">{html.escape(str(v))}</td>'


def table_html(df, cols: list[str], ident: str) -> str:
    head = "".join(f"<th>{html.escape(c)}</th>" for c in cols)
    body = "".join("<tr>" + "".join(_cell(v) for v in row) + "</tr>" for row in df[cols].itertuples(index=False))
    return f'<table class="sortable" id="{html.escape(ident)}"><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>'


def _img(path: Path) -> str:
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return f'<figure><img alt="{html.escape(path.stem)}" src="data:image/png;base64,{data}"></figure>'


def write_page(sr, folder: Path, tables: dict) -> list[str]:
    lb = tables.get("leaderboard.csv")
    if lb is None:
        return []
    c = sr.config
    succ = [col for col in lb.columns if col.startswith("success_")]
    cols = ["rank", "solver", "track", "score", "ci_low", "ci_high", "instances", "better_than"] + succ
    parts = [f"<h1>{html.escape(c.title or c.name)}</h1>",
             f"<p>Pose sets {html.escape(c.pose_sets)}; budget {c.budget_per_dim} &times; dimension evaluations; "
             f"{c.runs} runs per pose; targets {html.escape(', '.join(f'{t:.0e}' for t in c.targets))}. "
             "Score: normalised area under the ECDF (higher is better) with a 95 % bootstrap interval; "
             f"better_than: significant at &alpha; = {c.alpha}, Holm-corrected within the table. "
             "Click a column header to sort.</p>"]
    for k, (scope, g) in enumerate(lb.groupby("scope", sort=False)):
        parts += [f"<h2>{html.escape(scope)}</h2>", table_html(g, cols, "leaderboard" if k == 0 else f"lb-{k}")]
    figs = sorted(folder.glob("ecdf_*.png"))
    if figs:
        parts += ["<h2>Runtime distributions (ECDF)</h2>"] + [_img(p) for p in figs]
    ms = tables.get("measures.csv")
    if ms is not None:
        parts.append("<h2>Per problem</h2>")
        for k, (problem, g) in enumerate(ms.groupby("problem", sort=False)):
            parts += [f"<h3>{html.escape(problem)}</h3>",
                      table_html(g, ["set", "solver", "track", "target", "trials", "success_rate", "ert"], f"pp-{k}")]
    page = ("<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{html.escape(c.name)} leaderboard</title><style>{STYLE}</style></head><body>"
            + "\n".join(parts) + f"<script>{SCRIPT}</script></body></html>\n")
    (folder / "index.html").write_text(page, encoding="utf-8")
    return ["index.html"]
