"""The pieces of index.html (put together by :func:`fkopt.kinbench.reports.html_page`): one
self-contained static page -- sortable tables (a few lines of inline JavaScript: a click on a
header sorts by that column, again reverses), figures inline as ``data:`` URIs. Nothing is loaded
from the network."""
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
td.t { text-align: left; white-space: nowrap; } img { max-width: 100%; }
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


def img(path: Path) -> str:
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return f'<figure><img alt="{html.escape(path.stem)}" src="data:image/png;base64,{data}"></figure>'


def page(title: str, body: list[str]) -> str:
    return ("<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{html.escape(title)}</title><style>{STYLE}</style></head><body>"
            + "\n".join(body) + f"<script>{SCRIPT}</script></body></html>\n")
