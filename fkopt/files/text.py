"""Text fkopt prints or writes from values it did not choose: strict JSON for ``--json``,
Markdown-escaped text, and one-line excerpts of a hostile file's text for error lines."""
from __future__ import annotations

import json
import math
from typing import Any

import numpy as np


def strict_json(data: Any, **dump) -> str:
    """``data`` as strict JSON (RFC 8259: no ``NaN``/``Infinity``, which strict parsers reject),
    for every ``--json`` output: a number that is not finite becomes ``null`` and the object gets
    a ``"non_finite"`` mapping from that field's path (``position_error``, ``solutions[0].x``)
    to ``"inf"``, ``"-inf"`` or ``"nan"`` -- nothing is lost, nothing guessed (docs/cli.md)."""
    flags: dict[str, str] = {}

    def clean(value, path):
        if isinstance(value, dict):
            return {k: clean(v, f"{path}.{k}" if path else str(k)) for k, v in value.items()}
        if isinstance(value, np.ndarray):
            value = value.tolist()
        if isinstance(value, (list, tuple)):
            return [clean(v, f"{path}[{i}]") for i, v in enumerate(value)]
        if isinstance(value, (bool, np.bool_)):
            return bool(value)
        if isinstance(value, np.integer):
            return int(value)
        if isinstance(value, (float, np.floating)):
            value = float(value)
            if not math.isfinite(value):
                flags[path] = "nan" if value != value else ("inf" if value > 0 else "-inf")
                return None
        return value
    out = clean(data, "")
    if flags and isinstance(out, dict):
        out["non_finite"] = flags
    return json.dumps(out, allow_nan=False, default=str, **dump)



#: Characters that mean something in Markdown tables, links, code or HTML, and their escapes.
_MD_ESCAPES = {"\\": "\\\\", "`": "\\`", "*": "\\*", "[": "\\[", "]": "\\]", "|": "\\|",
               "<": "&lt;", ">": "&gt;", "&": "&amp;"}


def md_text(value: Any) -> str:
    """``value`` as literal text inside a Markdown file (a table cell, a heading): HTML (``<script>``,
    ``<img onerror>``) and entities, link and image brackets, table bars, code ticks and
    emphasis stars escaped; newlines, terminal escape sequences and other control characters
    shown as ``\\xNN`` text instead of acting (a title cannot start a new heading or recolour a
    terminal that shows the file)."""
    out = []
    for c in str(value):
        if c in _MD_ESCAPES:
            out.append(_MD_ESCAPES[c])
        elif not c.isprintable():
            out.append(f"\\\\x{ord(c):02x}" if ord(c) < 256 else f"\\\\u{ord(c):04x}")
        else:
            out.append(c)
    return "".join(out)


def short_token(text: Any, limit: int = 40) -> str:
    """A short, printable excerpt of a hostile file's text for an error line: whitespace runs
    made one space, non-printable characters ``?``, at most ``limit`` characters."""
    text = " ".join(str(text).split())
    text = "".join(c if c.isprintable() else "?" for c in text)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def one_line(text: str, limit: int = 2000) -> str:
    """``text`` safe to print as one line: control characters escaped, long text cut."""
    text = "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))
    return text if len(text) <= limit else text[: limit - 3] + "..."


def md_table(df) -> str:
    """A pandas table as a Markdown table (4 significant digits; ``_(empty)_`` when it has no rows)."""
    if df.empty:
        return "_(empty)_"
    return df.to_markdown(index=False, floatfmt=".4g")
