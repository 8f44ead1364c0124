"""Checks and messages of what a user wrote in a config file or on the command line: one line
``field.path: message`` from a pydantic ``ValidationError`` (:func:`error_line`), the closest
allowed name (:func:`did_you_mean`), text refused where a number belongs
(:func:`no_quoted_numbers`), ``paper`` / ``name`` as single safe path components
(:func:`check_component`), and the largest magnitude of a number taken where no schema
bounds it (:data:`MAX_MAGNITUDE`).

pydantic is imported inside :func:`models_in`: it is a large part of a light command's start-up
(``fkopt fk`` on a preset never imports it, docs/design.md "Start-up")."""
from __future__ import annotations

import difflib
import math
import re
import types
import typing
from typing import Any

from fkopt.errors import FkoptError
from fkopt.files.text import short_token

#: Largest magnitude of a number fkopt takes from a user's file or command line where no
#: schema bounds it (URDF lengths and angles, --joints/--pose values), in the file's own units:
#: 1e9 m is six times the Earth-Sun distance, 1e9 deg 2.8 million turns. Past it a value is a
#: typo or an attack, and its square in FK or a Jacobian overflows to inf (docs/reliability.md).
MAX_MAGNITUDE = 1e9
#: ``paper`` and ``name``: one path component, letter or digit first.
MAX_COMPONENT = 64
COMPONENT_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9_.+-]{0,63}$"
_COMPONENT = re.compile(COMPONENT_PATTERN)


def models_in(annotation) -> list:
    """The pydantic models an annotation can hold (through Optional/Union, list, dict, Annotated)."""
    from pydantic import BaseModel
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [m for arg in typing.get_args(annotation) for m in models_in(arg)]


def field_names_at(model, loc: list[str]) -> list[str]:
    """The field names (and aliases) a mapping at ``loc`` (an error's location without its last
    part) may have, walking ``model``'s annotations; [] where that is not known."""
    current = models_in(model)
    for part in loc:
        if part.isdigit() or part.startswith(("list[", "function-", "literal[", "dict[")):
            continue                         # list items and validator frames: same models
        tagged = [m for m in current if m.__name__ == part]
        if tagged:                           # a union branch pydantic tried
            current = tagged
            continue
        current = [m for c in current if part in c.model_fields for m in models_in(c.model_fields[part].annotation)]
    names = []
    for c in current:
        for key, info in c.model_fields.items():
            names += [key] + ([info.alias] if info.alias else [])
    return sorted(set(names))


def _numeric_only(annotation) -> bool:
    """Whether a field's type takes numbers (int, float, bool; Optional of them) and no text."""
    if annotation in (int, float, bool):
        return True
    args = typing.get_args(annotation)
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _numeric_only(args[0])
    if origin in (typing.Union, getattr(types, "UnionType", None)) and args:
        kinds = [a for a in args if a is not type(None)]
        return bool(kinds) and all(_numeric_only(a) for a in kinds)
    return False


def no_quoted_numbers(cls, value, info):
    """A pydantic ``field_validator("*", mode="before")``: text where a number belongs is refused
    (``iterations: "300"``), as a YAML file means a number only unquoted; pydantic's lax mode
    would turn "300" into 300 silently. Lists of numbers are checked item by item. Fields that
    also take text (a union with str or a Literal) keep it."""
    field = cls.model_fields.get(info.field_name) if info.field_name else None
    if field is None:
        return value
    annotation = field.annotation
    items = None
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if typing.get_origin(annotation) is typing.Union or type(None) in args:    # Optional[list[float]]
        kinds = [a for a in args if a is not type(None)]
        if len(kinds) == 1:
            annotation = kinds[0]
            origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin in (list, tuple) and args:
        inner = [a for a in args if a is not Ellipsis]
        if inner and all(_numeric_only(a) for a in inner) and isinstance(value, (list, tuple)):
            items = value
    elif origin is dict and len(args) == 2 and _numeric_only(args[1]) and isinstance(value, dict):
        items = list(value.values())
    if isinstance(value, str) and _numeric_only(annotation):
        raise ValueError(_text_for_number(value, "a number"))
    for v in items or ():
        if isinstance(v, str):
            raise ValueError(_text_for_number(v, "numbers"))
    return value


def _text_for_number(text: str, wanted: str) -> str:
    try:
        number = float(text)
    except ValueError:
        return f"needs {wanted}, got the text {short_token(repr(text))}"
    if not math.isfinite(number):
        return f"needs {wanted} (finite), got the text {short_token(repr(text))}"
    return f"needs {wanted}, got the text {short_token(repr(text))} (write it without quotes)"


def field_path(loc) -> str:
    """A field's path as every message of fkopt writes it: names joined by dots, list items by
    index in brackets (``cases[0].pose``, ``algorithms[1].params.limit``), from a pydantic
    error's ``loc`` (list indices are ints there)."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def did_you_mean(word: str, names) -> str:
    """`` (did you mean 'x'?)`` for the closest of ``names`` (difflib, as the CLI's options), else ``""``."""
    close = difflib.get_close_matches(str(word), [str(n) for n in names], n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""


def error_line(err, branches: dict[str, dict[str, str]] | None = None, data: dict | None = None,
               model=None) -> str:
    """One line ``field.path: message`` from a pydantic ``ValidationError``.

    ``branches`` maps a union field to ``{key in the user's mapping: branch tag}``, so that the
    error of the branch the user meant (by its key) is reported, not the first branch tried.
    With ``model`` (the validated class), an unknown field names the closest allowed one, and
    such a typo is reported before the "Field required" it causes (``algoritms`` before
    ``algorithms``).
    """
    errors = err.errors()
    if model is not None:     # a misspelt field first: its "missing" twin follows from it
        hint = {id(e): did_you_mean(e["loc"][-1], field_names_at(model, [str(p) for p in e["loc"][:-1]]))
                for e in errors if e["type"] == "extra_forbidden"}
        errors = sorted(errors, key=lambda e: 0 if hint.get(id(e)) else 1)
    else:
        hint = {}
    wanted: dict[str, str] = {}
    tags: set[str] = set()
    for field, table in (branches or {}).items():
        tags |= set(table.values())
        value = (data or {}).get(field)
        if isinstance(value, dict):
            hit = next((tag for key, tag in table.items() if key in value), None)
            if hit:
                wanted[field] = hit
        elif isinstance(value, list):
            wanted[field] = "list["
    for e in errors:
        loc = [str(p) for p in e["loc"]]
        if loc and loc[0] in wanted and len(loc) > 1:
            branch = loc[1]
            union = branch in tags or branch.startswith("list[")
            if union and not branch.startswith(wanted[loc[0]]):
                continue
        loc = [p for p in e["loc"] if isinstance(p, int)
               or (p not in tags and not str(p).startswith(("function-", "list[", "literal[")))]
        msg = e["msg"].removeprefix("Value error, ")
        if e["type"] == "extra_forbidden":
            msg = "unknown field" + (hint.get(id(e)) or "")
        return f"{field_path(loc)}: {msg}" if loc else msg
    return str(err).splitlines()[0]



def check_component(value: Any, field: str) -> str:
    """``value`` as one safe path component, else a one-line error naming ``field``."""
    if not isinstance(value, str) or not _COMPONENT.match(value):
        shown = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "..."
        raise FkoptError(f"{field}: {shown} is not a single safe folder name: letters, digits and "
                         f"_ . + - only, a letter or digit first, at most {MAX_COMPONENT} characters")
    return value
