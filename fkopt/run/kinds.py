"""The registry of config kinds: name -> :class:`~fkopt.run.tasks.Kind` (function objects).

A kind registers itself when its module is imported (:func:`register`), so the engine imports no
kind: :mod:`fkopt.kinds` registers ``experiment``, ``study`` and ``assembly``, and
:mod:`fkopt.kinbench` registers ``suite`` (importing :mod:`fkopt.kinbench` registers all four;
the command line and :mod:`fkopt.reproduce` do). Adding a kind is one package with a ``kind.py``
that calls :func:`register`, imported by its parent package.
"""
from __future__ import annotations

from fkopt.errors import FkoptError
from fkopt.run.tasks import Kind

#: kind name -> its :class:`~fkopt.run.tasks.Kind`, in registration order.
KINDS: dict[str, Kind] = {}


def register(kind: Kind) -> Kind:
    """Add ``kind`` to :data:`KINDS` (once per name) and return it."""
    if kind.name in KINDS and KINDS[kind.name] is not kind:
        raise FkoptError(f"config kind '{kind.name}' is registered twice")
    KINDS[kind.name] = kind
    return kind


def kind_of(name: str | None) -> Kind:
    """The kind a file's ``kind:`` key names (an experiment file has none)."""
    key = name or "experiment"
    if key not in KINDS:
        raise FkoptError(f"kind: '{name}' unknown; allowed: {', '.join(k for k in KINDS if k != 'experiment')} "
                         "(an experiment file has no kind)")
    return KINDS[key]


def config_kind(config) -> Kind:
    """The kind of a validated config object."""
    return kind_of(getattr(config, "kind", None))


def stored_kind(meta: dict) -> Kind | None:
    """The kind of a stored result from its meta.json (None: a kind not registered here, or a
    ``kind`` that is not a name)."""
    config = meta.get("config") if isinstance(meta.get("config"), dict) else {}
    name = meta.get("kind") or config.get("kind") or "experiment"
    return KINDS.get(name) if isinstance(name, str) else None
