"""The one registry: every solver and mechanism fkopt can name, each entry carrying its own facts.

A **solver entry** (:class:`SolverEntry`) is a function object (a class) and what is known about
it: its ``role`` (an ``optimiser`` minimising a problem through :func:`fkopt.solve`, or an ``ik``
/ ``fk`` solver answering one query at a time on kinbench's clock track), its kinbench
``track``, the ``package`` it runs through (``fkopt`` or the PyPI package of another library),
how kinbench ``timing`` measures it and the ``display`` name figures and tables print. Three
families share it: fkopt's algorithms and exact solvers, other libraries' optimisers (the
``scipy:``, ``pymoo:`` and ``niapy:`` adapters, :data:`ADAPTER_FAMILIES`) and the field's IK/FK
solvers through their own packages (:mod:`fkopt.adapters.field`). **Adding an outside solver**:
one wrapper class in ``fkopt/adapters/field/`` (``name``, ``package``, ``settings``, ``solve1``;
its package imported inside it, run as its authors run it) and one :class:`SolverEntry` line in
:data:`SOLVERS`; docs/kinbench.md gets its protocol row.

A name resolves, in this order, to

1. a **built-in** entry of :data:`MECHANISMS` / :data:`SOLVERS` (function objects; adding one to
   fkopt is one module plus one line here);
2. an **adapter** of another library's optimiser (algorithms only): the reserved prefixes
   ``scipy:``, ``pymoo:`` and ``niapy:`` (e.g. ``"pymoo:DE"``), see :mod:`fkopt.adapters`;
3. an **entry point** of an installed package, in the groups ``fkopt.mechanisms`` and
   ``fkopt.algorithms`` (``[project.entry-points."fkopt.algorithms"] de = "mypkg.de:DE"``).
   Entry points are read only when a name is not built in (or when listing), so ``fkopt fk
   3-rps`` never scans installed packages;
4. a **direct reference** ``package.module:Class`` (a user's plug-in: the only names given as
   strings).

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
from importlib.metadata import entry_points as _eps
from pathlib import Path
from typing import Callable

from fkopt.adapters import adapter_class
from fkopt.adapters.field.cmaes import CmaES
from fkopt.adapters.field.eaik import EAIK
from fkopt.adapters.field.ikpy import IkPy
from fkopt.adapters.field.lbfgsb import LBFGSB
from fkopt.adapters.field.nevergrad_ngopt import NGOpt
from fkopt.adapters.field.optik import OptIK
from fkopt.adapters.field.pin import PinCLIK
from fkopt.adapters.field.pink import Pink
from fkopt.adapters.field.rtb import RtbLM, RtbNR
from fkopt.adapters.field.scipy_fk import LeastSquaresFK
from fkopt.adapters.field.torchkin import TorchIK
from fkopt.adapters.field.tracik import TracIK
from fkopt.adapters.field.track_entries import EAIKAll, RtbLMRestarts, RtbLMSeeded, TracIKRestarts, TracIKSeeded
from fkopt.adapters.libraries import ADAPTERS, DISTRIBUTIONS
from fkopt.algorithms.abc import ABC
from fkopt.algorithms.abc_wang7dof import ABCWang7dof
from fkopt.algorithms.aco import ACO
from fkopt.algorithms.base import Algorithm
from fkopt.algorithms.dls import DLS
from fkopt.algorithms.gabc import GABC
from fkopt.algorithms.hybrid import ABCLM, GABCLM, PSOLM
from fkopt.algorithms.lm import LM
from fkopt.algorithms.nr import NR
from fkopt.algorithms.pabc import PABC
from fkopt.algorithms.pso import PSO
from fkopt.errors import FkoptError, did_you_mean
from fkopt.files import did_you_mean as closest
from fkopt.kinematics.as_algorithms import Exact, Forward, Inverse
from fkopt.kinematics.kinbench_entries import FkoptAllSolutions, FkoptForward, FkoptInverse, FkoptPath
from fkopt.mechanisms.base import Mechanism, ParallelMechanism, SerialMechanism
from fkopt.mechanisms.catalog import MECHANISMS

#: Roles of a solver: minimises a problem (fkopt.solve) / answers one IK or FK query (the clock) /
#: gives every IK solution of a pose (``solutions(T)``) / follows a path (``path(T, start)``).
OPTIMISER, IK, FK, ALL_SOLUTIONS, PATH = "optimiser", "ik", "fk", "all-solutions", "path"
#: How kinbench times each role.
COUNTED = "evaluations counted by fkopt; process time per run (timing.csv)"
PER_QUERY = "one query per call, wall clock, on one core (kinbench's clock track)"


@dataclass(frozen=True)
class SolverEntry:
    """One solver fkopt can name, with its facts: the class (``make``), its role, kinbench
    track, package, timing rule and display name."""

    name: str
    make: Callable            # an Algorithm class (optimiser) or a one-query wrapper class (ik / fk)
    role: str                 # OPTIMISER, IK or FK
    track: str | None         # kinbench's evaluations track of an optimiser; "clock" for ik / fk; or
                              # "all-solutions" / "paths" (fkopt.kinbench.solution_sets, .paths)
    package: str = "fkopt"    # the PyPI package it runs through
    timing: str = COUNTED
    display: str = ""         # the name on figures and tables ("" -> the name)

    @property
    def label(self) -> str:
        return self.display or self.name


def _optimiser(name, cls, track, display=""):
    return SolverEntry(name, cls, OPTIMISER, track, "fkopt", COUNTED, display)


def _field(cls, role=IK, display="", track="clock"):
    return SolverEntry(cls.name, cls, role, track, cls.package, PER_QUERY, display)


#: Every built-in solver: fkopt's algorithms and exact solvers, and the field's solvers through
#: their own packages (the library adapters are :data:`ADAPTER_FAMILIES`).
SOLVERS: dict[str, SolverEntry] = {e.name: e for e in (
    _optimiser("abc", ABC, "black-box", "ABC"),
    _optimiser("abc-wang7dof", ABCWang7dof, "black-box", "ABC (wang7dof eqs. 7-8)"),   # the ABC as wang7dof prints it
    _optimiser("gabc", GABC, "black-box", "GABC"),
    _optimiser("aco", ACO, "black-box", "ACO"),
    _optimiser("pso", PSO, "black-box", "PSO"),
    _optimiser("pabc", PABC, "black-box", "P-ABC"),
    _optimiser("nr", NR, "jacobian", "Newton-Raphson"),
    _optimiser("lm", LM, "jacobian", "Levenberg-Marquardt"),
    _optimiser("dls", DLS, "jacobian"),
    _optimiser("abc+lm", ABCLM, "jacobian"),
    _optimiser("gabc+lm", GABCLM, "jacobian"),
    _optimiser("pso+lm", PSOLM, "jacobian"),
    _optimiser("forward", Forward, "exact"),     # fkopt.forward as a solver (parallel FK)
    _optimiser("inverse", Inverse, "exact"),     # fkopt.inverse as a solver (serial IK)
    _optimiser("exact", Exact, "exact"),         # forward or inverse, by the mechanism's kind
    _field(FkoptInverse),                        # fkopt.inverse, one query per call
    _field(FkoptForward, FK),
    _field(LeastSquaresFK, FK),                  # scipy least_squares: the FK reference
    _field(TracIK),
    _field(RtbLM),
    _field(RtbNR),
    _field(PinCLIK),
    _field(IkPy),
    _field(CmaES),
    _field(LBFGSB),
    _field(NGOpt),
    _field(EAIK),                                # analytic; "not applicable" where it cannot decompose
    _field(OptIK),
    _field(Pink),
    _field(TorchIK),                             # batched: the throughput track (tracks.throughput.solvers)
    _field(FkoptAllSolutions, ALL_SOLUTIONS, track="all-solutions"),   # fkopt.inverse(solutions="all")
    _field(EAIKAll, ALL_SOLUTIONS, track="all-solutions"),             # EAIK's analytic set
    _field(RtbLMRestarts, ALL_SOLUTIONS, track="all-solutions"),       # ik_LM from random starts, fkopt's time
    _field(TracIKRestarts, ALL_SOLUTIONS, track="all-solutions"),      # TRAC-IK from random starts, fkopt's time
    _field(FkoptPath, PATH, track="paths"),                            # fkopt.inverse_path
    _field(RtbLMSeeded, PATH, track="paths"),                          # ik_LM seeded with the previous answer
    _field(TracIKSeeded, PATH, track="paths"),                         # TRAC-IK seeded with the previous answer
)}

#: fkopt's optimisers by name (what ``fkopt.solve`` and config files name).
ALGORITHMS: dict[str, type] = {n: e.make for n, e in SOLVERS.items() if e.role == OPTIMISER}
#: The field's one-query IK and FK solvers by name (kinbench's clock track).
IK_SOLVERS: tuple[str, ...] = tuple(n for n, e in SOLVERS.items() if e.role == IK)
FK_SOLVERS: tuple[str, ...] = tuple(n for n, e in SOLVERS.items() if e.role == FK)
#: The entries of kinbench's all-solutions and paths tracks.
ALL_SOLUTIONS_SOLVERS: tuple[str, ...] = tuple(n for n, e in SOLVERS.items() if e.role == ALL_SOLUTIONS)
PATH_SOLVERS: tuple[str, ...] = tuple(n for n, e in SOLVERS.items() if e.role == PATH)


@dataclass(frozen=True)
class AdapterFamily:
    """Other libraries' optimisers under a reserved prefix (``pymoo:DE``): the class is made on
    demand by ``make(method)``; kinbench's track is the black box (they see the fitness only)."""

    prefix: str
    make: Callable
    package: str
    track: str = "black-box"
    timing: str = COUNTED


ADAPTER_FAMILIES: dict[str, AdapterFamily] = {
    p: AdapterFamily(p, lambda method, p=p: adapter_class(p, method), DISTRIBUTIONS[p]) for p in ADAPTERS}


def solver_entry(name: str) -> SolverEntry | None:
    """The built-in entry of ``name``, else None (adapters and plug-ins: :func:`track_of`)."""
    return SOLVERS.get(name)


def track_of(name: str) -> str | None:
    """The kinbench track of a built-in solver or an adapter; None for anything else (a plug-in)."""
    if name in SOLVERS:
        return SOLVERS[name].track
    prefix = name.split(":", 1)[0]
    return ADAPTER_FAMILIES[prefix].track if ":" in name and prefix in ADAPTER_FAMILIES else None


def display_name(name: str) -> str:
    """The name figures and tables print for a solver (its own name when it has no other)."""
    entry = SOLVERS.get(name)
    return entry.label if entry is not None else name


def clock_solver(name: str, mechanism, *, timeout: float, rng, **options):
    """The one-query solver ``name`` (:data:`IK_SOLVERS`, :data:`FK_SOLVERS`; or an entry of the
    all-solutions and paths tracks, ``options`` = its ``fixed`` joints) built on ``mechanism``; a
    missing package or a mechanism the package cannot read is one line."""
    entry = SOLVERS.get(name)
    if entry is None or entry.role == OPTIMISER:
        raise FkoptError(f"unknown field solver '{name}'; allowed: {', '.join(IK_SOLVERS + FK_SOLVERS)}")
    try:
        return entry.make(mechanism, timeout=timeout, rng=rng, **options)
    except ImportError as err:
        extra = getattr(entry.make, "extra", "field")       # torch is an extra of its own
        raise FkoptError(f"field solver '{name}' needs {entry.package} (pip install -e \".[{extra}]\"): "
                         f"{err}") from None
    except FkoptError:       # NotApplicable included: the board shows a "not applicable: why" cell
        raise
    except Exception as err:     # the outside package refused this arm: one line, not its traceback
        raise FkoptError(f"field solver '{name}' ({entry.package}) cannot read "
                         f"{getattr(mechanism, 'path', 'this arm')}: {type(err).__name__}: "
                         f"{str(err).splitlines()[0][:160] if str(err) else ''}") from None


#: Prefixes reserved for the adapters of other libraries' optimisers (fkopt.adapters).
ADAPTER_PREFIXES = tuple(ADAPTER_FAMILIES)

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
    target: str    # where it lives: "module.Class" (built-in) or an entry point's "module:Class"
    origin: str    # "built-in", "adapter", "entry point (distribution 1.0)"


def _base(kind: str) -> type:
    return Mechanism if kind == "mechanism" else Algorithm


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
        family = ("parallel" if issubclass(obj, ParallelMechanism)
                  else "serial" if issubclass(obj, SerialMechanism) else None)
        if family is None:
            raise FkoptError(f"mechanism plug-in '{where}' must subclass ParallelMechanism or SerialMechanism")
        family_base = ParallelMechanism if family == "parallel" else SerialMechanism
        missing = [] if hasattr(obj, "name") else ["name"]
        missing += [m for m in REQUIRED["mechanism"][family] if getattr(obj, m) is getattr(family_base, m)]
    else:
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
    out = {}
    for ep in _eps(group=GROUPS[kind]):
        dist = getattr(ep, "dist", None)
        origin = f"{dist.name} {dist.version}" if dist is not None else "unknown distribution"
        out.setdefault(ep.name, (ep.value, origin, ep))
    return out


def _load(table: dict[str, type], kind: str, name: str):
    if not isinstance(name, str) or not name:
        raise FkoptError(f"{kind} name must be a non-empty string, got {name!r}")
    if name in table:
        return table[name]
    prefix, sep, rest = name.partition(":")
    if sep and prefix in ADAPTER_FAMILIES:
        if kind != "algorithm":
            raise FkoptError(f"'{name}': the prefix '{prefix}:' is reserved for algorithm adapters")
        return ADAPTER_FAMILIES[prefix].make(rest)
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
    # fkopt.files.did_you_mean: the one "did you mean" of field names too
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
    out = dict(geometry)
    for key in fields:
        value = out.get(key)
        if isinstance(value, str) and value and not Path(value).is_absolute():
            out[key] = str(Path(folder) / value)
    return out


def entries(kind: str) -> list[Entry]:
    """Every name of ``kind`` fkopt knows without a direct reference, with its origin."""
    table = MECHANISMS if kind == "mechanism" else ALGORITHMS
    out = [Entry(kind, n, f"{c.__module__}.{c.__qualname__}", "built-in") for n, c in table.items()]
    if kind == "algorithm":
        out += [Entry(kind, f"{p}:{n}", t, f"adapter ({p}, {'optional' if p != 'scipy' else 'core'})")
                for p, names in ADAPTERS.items() for n, t in names.items()]
    out += [Entry(kind, n, t, f"entry point ({origin})")
            for n, (t, origin, _) in entry_points(kind).items() if n not in table]
    return out
