"""The one YAML reader of fkopt's config and geometry files (:func:`load_yaml`): refused with a
one-line :class:`~fkopt.errors.FkoptError` are files larger than
:data:`~fkopt.files.reading.MAX_YAML_BYTES`, bytes that are not UTF-8, YAML aliases (``*name``;
anchors and aliases are refused altogether, so a tiny file cannot expand into gigabytes --
fkopt's configs never need them), duplicate keys (the error names the key and its line),
nesting deeper than :data:`MAX_YAML_DEPTH`, NaN and infinite numbers (``.nan``, ``.inf``,
``1e400``: no field of any fkopt file takes them), and malformed YAML (line and column). Only
plain data is built (``yaml.SafeLoader``): no tag ever runs code.

PyYAML is imported inside the functions: the command line imports this package at start-up,
and ``fkopt ik`` without ``--geometry`` reads no YAML (docs/design.md, "Start-up")."""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from fkopt.errors import FkoptError
from fkopt.files.reading import MAX_YAML_BYTES, read_text

#: Deepest nesting of YAML collections accepted.
MAX_YAML_DEPTH = 32


def _loader():
    import yaml

    class Loader(yaml.SafeLoader):
        """SafeLoader without aliases, without duplicate keys, with bounded depth."""

        depth = 0

        def compose_node(self, parent, index):
            if self.check_event(yaml.AliasEvent):
                event = self.peek_event()
                raise yaml.composer.ComposerError(None, None, "YAML anchors and aliases (&name, *name) "
                                                  "are not accepted in fkopt files; write the values out", event.start_mark)
            event = self.peek_event()
            if getattr(event, "anchor", None):
                raise yaml.composer.ComposerError(None, None, "YAML anchors and aliases (&name, *name) "
                                                  "are not accepted in fkopt files; write the values out", event.start_mark)
            self.depth += 1
            try:
                if self.depth > MAX_YAML_DEPTH:
                    raise yaml.composer.ComposerError(None, None, f"nested deeper than {MAX_YAML_DEPTH} "
                                                      "levels", event.start_mark)
                return super().compose_node(parent, index)
            finally:
                self.depth -= 1

        def construct_yaml_float(self, node):
            value = super().construct_yaml_float(node)
            if value != value or value in (float("inf"), float("-inf")):
                raise yaml.constructor.ConstructorError(None, None, f"'{node.value}' is not a finite "
                                                        "number (NaN and inf are not accepted)",
                                                        node.start_mark)
            return value

        def construct_mapping(self, node, deep=False):
            seen = {}
            for key_node, _ in node.value:
                key = self.construct_object(key_node, deep=True)
                try:
                    hash(key)
                except TypeError:
                    raise yaml.constructor.ConstructorError(None, None, "a mapping key must be a plain "
                                                            "value", key_node.start_mark) from None
                if key in seen:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"duplicate key '{key}' (first at line {seen[key] + 1})",
                        key_node.start_mark)
                seen[key] = key_node.start_mark.line
            for key_node, value_node in node.value:      # a non-finite number names its field
                if value_node.tag == "tag:yaml.org,2002:float":
                    try:
                        self.construct_yaml_float(value_node)
                    except yaml.constructor.ConstructorError as err:
                        raise yaml.constructor.ConstructorError(
                            None, None, f"{self.construct_object(key_node, deep=True)}: {err.problem}",
                            value_node.start_mark) from None
            return super().construct_mapping(node, deep=deep)

    Loader.add_constructor("tag:yaml.org,2002:float", Loader.construct_yaml_float)
    # YAML 1.2's floats without a dot (1e-10, 2E5), which PyYAML (YAML 1.1) reads as text: a file
    # writes `threshold: 1e-10` and means a number, and text is refused where a number belongs
    # (no_quoted_numbers), so a quoted "300" stays text and is refused with one line
    Loader.add_implicit_resolver("tag:yaml.org,2002:float", re.compile(r"^[-+]?[0-9][0-9_]*[eE][-+]?[0-9]+$"),
                                 list("-+0123456789"))
    return Loader


def load_yaml(path: str | Path, max_bytes: int = MAX_YAML_BYTES) -> Any:
    """Parse a YAML file with the limits above; errors name the file and the line."""
    import yaml
    text = read_text(path, max_bytes)
    try:
        return yaml.load(text, Loader=_loader())  # noqa: S506 - a SafeLoader subclass
    except yaml.MarkedYAMLError as err:
        mark = err.problem_mark or err.context_mark
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise FkoptError(f"{path}: malformed YAML{where}: {err.problem or err.context}") from None
    except yaml.YAMLError as err:
        raise FkoptError(f"{path}: malformed YAML: {err}") from None
    except RecursionError:
        raise FkoptError(f"{path}: nested too deeply") from None


def load_mapping(path: str | Path, what: str) -> dict:
    """A YAML file whose top level must be a mapping (``what`` says of what)."""
    data = load_yaml(path)
    if not isinstance(data, dict):
        raise FkoptError(f"{path}: expected a mapping of {what} at the top level")
    bad = [k for k in data if not isinstance(k, str)]
    if bad:
        raise FkoptError(f"{path}: field names must be text, got {bad[0]!r}")
    return data
