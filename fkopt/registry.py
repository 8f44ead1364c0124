"""Name -> implementation maps for mechanisms and algorithms, built-in and plug-in.

A name resolves, in this order, to

1. a **built-in** entry of :data:`MECHANISMS` / :data:`ALGORITHMS` (``"module:Class"`` strings
   imported on first use, so listing names costs nothing). Adding one to fkopt is one module
   plus one line here;
2. an **adapter** of another library's optimiser (algorithms only): the reserved prefixes
   ``scipy:``, ``pymoo:`` and ``niapy:`` (e.g. ``"pymoo:DE"``), see :mod:`fkopt.adapters`;
3. an **entry point** of an installed package, in the groups ``fkopt.mechanisms`` and
   ``fkopt.algorithms`` (``[project.entry-points."fkopt.algorithms"] de = "mypkg.de:DE"``).
   Entry points are read only when a name is not built in (or when listing), so ``fkopt fk
   3-rps`` never scans installed packages;
4. a **direct reference** ``package.module:Class``.

Whatever an entry point or a direct reference names is checked *before anything is called*:
it must be a class and a subclass of fkopt's documented base
(:class:`fkopt.mechanisms.base.Mechanism`, :class:`fkopt.algorithms.base.Algorithm`);
anything else -- a function such as ``subprocess:run``, a module attribute that is not a
class, a class of the wrong kind -- is refused with one line naming it. (Importing the named
module runs its top level, as any ``import`` does; only installed or importable modules can be
named, and nothing they define is *called* unless it passed the check.)

Every failure is one :class:`~fkopt.errors.FkoptError` line naming the plug-in: an unknown
name, an entry point or module that fails to import, a class missing a required method.

The named attribute is read from the module's namespace itself (``module.__dict__``), never
through ``getattr``: a module-level ``__getattr__`` of the plug-in's module is not called
before the subclass check.

Where fkopt reads names out of files it did not write -- ``fkopt check`` of someone else's
results folder, whose ``meta.json`` names the mechanism and algorithms -- resolution runs
inside :func:`registered_only`: built-in names, adapters and *registered* entry points
resolve, a direct reference ``package.module:Class`` (which would import any installed
module) is refused with one line unless the user asked for it (``fkopt check
--allow-plugins``).
"""
from __future__ import annotations

import importlib
import re
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from functools import lru_cache

from .errors import FkoptError, did_you_mean

MECHANISMS: dict[str, str] = {
    "3-rps": "fkopt.mechanisms.rps3:ThreeRPS",
    "6-sps": "fkopt.mechanisms.sps6:SixSPS",
    "6-sps-cmm": "fkopt.mechanisms.sps6:SixSPSCMM",
    "3-rpupc-ups": "fkopt.mechanisms.rpupc_ups:ThreeRPUPcUPS",
    "3-ppr": "fkopt.mechanisms.ppr3:ThreePPR",
    "dh-arm": "fkopt.mechanisms.dh_arm:DHArm",
    "7dof-arm": "fkopt.mechanisms.dh_arm:SevenDofArm",
    "dh-chain": "fkopt.mechanisms.dh_chain:DHChain",   # seeded spatial chains, n joints (kinbench v3)
    "urdf": "fkopt.mechanisms.urdf:URDFArm",
    "mjcf": "fkopt.mechanisms.mjcf:MJCFArm",
}

ALGORITHMS: dict[str, str] = {
    "abc": "fkopt.algorithms.abc:ABC",
    "gabc": "fkopt.algorithms.gabc:GABC",
    "aco": "fkopt.algorithms.aco:ACO",
    "pso": "fkopt.algorithms.pso:PSO",
    "pabc": "fkopt.algorithms.pabc:PABC",
    "nr": "fkopt.algorithms.nr:NR",
    "lm": "fkopt.algorithms.lm:LM",
    "dls": "fkopt.algorithms.dls:DLS",
    "abc+lm": "fkopt.algorithms.hybrid:ABCLM",
    "gabc+lm": "fkopt.algorithms.hybrid:GABCLM",
    "pso+lm": "fkopt.algorithms.hybrid:PSOLM",
    "forward": "fkopt.exact:Forward",     # fkopt.forward as a solver (parallel FK)
    "inverse": "fkopt.exact:Inverse",     # fkopt.inverse as a solver (serial IK)
    "exact": "fkopt.exact:Exact",         # forward or inverse, by the mechanism's kind
}

#: Prefixes reserved for the adapters of other libraries' optimisers (fkopt.adapters).
ADAPTER_PREFIXES = ("scipy", "pymoo", "niapy")

#: Entry-point groups third-party packages register in.
GROUPS = {"mechanism": "fkopt.mechanisms", "algorithm": "fkopt.algorithms"}

#: Methods a plug-in class must provide (checked on the class, before it is instantiated).
REQUIRED = {"mechanism": {"parallel": ("ik",), "serial": ("fk",)},
            "algorithm": ("minimize",)}

#: True inside :func:`registered_only`: direct references are refused.
_REGISTERED_ONLY: ContextVar[bool] = ContextVar("fkopt_registered_only", default=False)

_REFERENCE = re.compile(r"^[A-Za-z_][\w]*(\.[A-Za-z_]\w*)*:[A-Za-z_]\w*$")


@dataclass(frozen=True)
class Entry:
    """One name fkopt can resolve and where it comes from (for ``fkopt list``)."""

    kind: str      # "mechanism" | "algorithm"
    name: str
    target: str    # "module:Class"
    origin: str    # "built-in", "adapter", "entry point (distribution 1.0)"


def _base(kind: str) -> type:
    if kind == "mechanism":
        from .mechanisms.base import Mechanism
        return Mechanism
    from .algorithms.base import Algorithm
    return Algorithm


def check_class(obj, kind: str, where: str):
    """Refuse ``obj`` unless it is a class deriving from fkopt's base of ``kind`` and
    overriding the required methods; nothing of ``obj`` is called."""
    base = _base(kind)
    if not isinstance(obj, type):
        raise FkoptError(f"{kind} plug-in '{where}' is a {type(obj).__name__}, not a class; a plug-in must "
                         f"be a subclass of {base.__module__}.{base.__qualname__}")
    if not issubclass(obj, base):
        raise FkoptError(f"{kind} plug-in '{where}' ({obj.__module__}.{obj.__qualname__}) does not subclass "
                         f"{base.__module__}.{base.__qualname__}; refused")
    if kind == "mechanism":
        from .mechanisms.base import ParallelMechanism, SerialMechanism
        family = ("parallel" if issubclass(obj, ParallelMechanism)
                  else "serial" if issubclass(obj, SerialMechanism) else None)
        if family is None:
            raise FkoptError(f"mechanism plug-in '{where}' must subclass ParallelMechanism or SerialMechanism")
        family_base = ParallelMechanism if family == "parallel" else SerialMechanism
        missing = [] if hasattr(obj, "name") else ["name"]
        missing += [m for m in REQUIRED["mechanism"][family] if getattr(obj, m) is getattr(family_base, m)]
    else:
        from .algorithms.base import Algorithm
        missing = [] if hasattr(obj, "name") else ["name"]
        # either the two-method protocol or a minimize of its own (adapters)
        if obj.minimize is Algorithm.minimize:
            missing += [m for m in ("initialize", "iterate") if getattr(obj, m) is getattr(Algorithm, m)]
    if missing:
        raise FkoptError(f"{kind} plug-in '{where}' ({obj.__module__}.{obj.__qualname__}) is missing "
                         f"{', '.join(missing)}")
    return obj


@contextmanager
def registered_only(active: bool = True):
    """Within the block, resolve only built-in names, adapters and registered entry points;
    a direct reference ``package.module:Class`` is refused before anything is imported."""
    token = _REGISTERED_ONLY.set(bool(active))
    try:
        yield
    finally:
        _REGISTERED_ONLY.reset(token)


def _import_target(target: str, kind: str, where: str):
    """The object ``module:attr`` names, read from the module's own namespace (a module-level
    ``__getattr__`` is never called); ``attr`` may be dotted (``Outer.Inner``)."""
    module, _, attr = target.partition(":")
    try:
        mod = importlib.import_module(module)
    except BaseException as err:   # the plug-in's own import failed (even SystemExit): name it
        if isinstance(err, (KeyboardInterrupt, GeneratorExit)):
            raise
        raise FkoptError(f"{kind} plug-in '{where}': cannot import {module} "
                         f"({type(err).__name__}: {err})") from None
    obj = mod
    for part in attr.split("[")[0].strip().split("."):     # "mod:Class [extra]" of an entry point
        space = getattr(obj, "__dict__", {})     # the namespace itself, no __getattr__
        if not isinstance(space, dict) and not hasattr(space, "get"):
            space = {}
        if part not in space:
            raise FkoptError(f"{kind} plug-in '{where}': module {module} has no attribute '{attr}'")
        obj = space[part]
    return obj


@lru_cache(maxsize=None)
def entry_points(kind: str) -> dict[str, tuple[str, str, object]]:
    """Installed entry points of ``kind``: name -> (target, distribution, EntryPoint)."""
    from importlib.metadata import entry_points as _eps
    out = {}
    for ep in _eps(group=GROUPS[kind]):
        dist = getattr(ep, "dist", None)
        origin = f"{dist.name} {dist.version}" if dist is not None else "unknown distribution"
        out.setdefault(ep.name, (ep.value, origin, ep))
    return out


def _load(table: dict[str, str], kind: str, name: str):
    if not isinstance(name, str) or not name:
        raise FkoptError(f"{kind} name must be a non-empty string, got {name!r}")
    if name in table:
        module, cls = table[name].split(":")
        return getattr(importlib.import_module(module), cls)
    prefix, sep, rest = name.partition(":")
    if sep and prefix in ADAPTER_PREFIXES:
        if kind != "algorithm":
            raise FkoptError(f"'{name}': the prefix '{prefix}:' is reserved for algorithm adapters")
        from .adapters import adapter_class
        return adapter_class(prefix, rest)
    eps = entry_points(kind)
    if name in eps:
        target, origin, ep = eps[name]
        try:
            obj = _import_target(target, kind, name)
        except FkoptError as err:
            raise FkoptError(f"{kind} plug-in '{name}' (entry point {target} from {origin}) failed to import: "
                             f"{str(err).split(': ', 1)[-1]}") from None
        return check_class(obj, kind, name)
    if sep and _REFERENCE.match(name):
        if _REGISTERED_ONLY.get():
            raise FkoptError(f"{kind} '{name}' is a direct reference to an installed module; checking stored "
                             "results imports only built-in names and registered entry points (fkopt check "
                             "--allow-plugins imports it, if you trust the results folder)")
        return check_class(_import_target(name, kind, name), kind, name)
    allowed = did_you_mean(name, [*table, *eps])
    from .files import did_you_mean as closest     # the one "did you mean" of field names too
    raise FkoptError(f"unknown {kind} '{name}'{closest(name, [*table, *eps])}; allowed: {allowed}, "
                     + ("scipy:NAME, pymoo:NAME, niapy:NAME, " if kind == "algorithm" else "")
                     + "or package.module:Class of an installed plug-in")


def mechanism_class(name: str):
    return _load(MECHANISMS, "mechanism", name)


def algorithm_class(name: str):
    return _load(ALGORITHMS, "algorithm", name)


def resolve_files(cls, geometry: dict, folder) -> dict:
    """``geometry`` with the file fields of mechanism ``cls`` (``cls.file_fields``, e.g. the URDF
    ``file``) made relative to ``folder`` (the config file's folder) when they are relative."""
    fields = getattr(cls, "file_fields", ())
    if folder is None or not fields:
        return dict(geometry)
    from pathlib import Path
    out = dict(geometry)
    for key in fields:
        value = out.get(key)
        if isinstance(value, str) and value and not Path(value).is_absolute():
            out[key] = str(Path(folder) / value)
    return out


def entries(kind: str) -> list[Entry]:
    """Every name of ``kind`` fkopt knows without a direct reference, with its origin."""
    table = MECHANISMS if kind == "mechanism" else ALGORITHMS
    out = [Entry(kind, n, t, "built-in") for n, t in table.items()]
    if kind == "algorithm":
        from .adapters import ADAPTERS
        out += [Entry(kind, f"{p}:{n}", t, f"adapter ({p}, {'optional' if p != 'scipy' else 'core'})")
                for p, names in ADAPTERS.items() for n, t in names.items()]
    out += [Entry(kind, n, t, f"entry point ({origin})")
            for n, (t, origin, _) in entry_points(kind).items() if n not in table]
    return out
