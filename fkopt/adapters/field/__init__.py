"""The field's solvers through their own packages (``pip install -e ".[field]"``), for kinbench v3.

Every IK wrapper here takes a fkopt URDF or MJCF arm (:class:`fkopt.mechanisms.urdf.URDFArm`,
:class:`fkopt.mechanisms.mjcf.MJCFArm`) and reads it as URDF (:func:`arm_urdf`: always the URDF
fkopt writes from its own parsed chain, never the robot's file as it stands -- roboticstoolbox
runs xacro on what it reads, and xacro evaluates ``${...}`` in any attribute, even in elements
fkopt ignores, issue 42; ``settings["urdf"]`` says so), is built
once per arm (the package parses the file, outside the clock) and answers one target pose at a
time: :meth:`FieldIK.solve1` takes a 4x4 tip frame in the arm's base frame (m) and returns the
joints in fkopt's public units (deg, m) or ``None`` when the package gave no answer, plus what
the package said about its own answer (``claimed``; kinbench never counts it,
:mod:`fkopt.kinbench.physical` re-checks every answer with fkopt's FK). :func:`solve` runs a
solver over many targets and times every query with ``time.perf_counter``.

Seeds: every start configuration is drawn from the ``numpy.random.Generator`` the wrapper is
given (no global RNG); a package whose internal restarts draw from its own RNG says so in its
``settings`` (TRAC-IK, roboticstoolbox).

``timeout`` (s) is each query's wall-clock allowance: packages with a wall-clock limit get it
(TRAC-IK), restart loops written here stop starting new searches once it has passed, and
packages with only iteration limits (roboticstoolbox) run to their limits -- the clock track
(:mod:`fkopt.kinbench.clock`) counts any answer later than the timeout as a failure at the timeout.

The wrappers are registered, with their package, track and timing rule, in the one solver
registry (:data:`fkopt.registry.SOLVERS`; :func:`fkopt.registry.clock_solver` builds one).
Modules, one per outside package: :mod:`.tracik` (pytracik), :mod:`.rtb`
(roboticstoolbox-python ``ik_LM``, ``ik_NR``), :mod:`.pin` (pinocchio's CLIK), :mod:`.ikpy`;
black-box optimisers on :func:`pose_objective` (:class:`BlackBoxIK`, restarts until the
timeout): :mod:`.cmaes` (pycma, IPOP), :mod:`.lbfgsb` (scipy L-BFGS-B from random starts),
:mod:`.nevergrad_ngopt` (NGOpt); analytic: :mod:`.eaik` (EAIK, every solution of the 1-6R arms
it decomposes; elsewhere :class:`NotApplicable`); FK of parallel mechanisms: :mod:`.scipy_fk` (scipy
``least_squares`` from random starts, :class:`~.scipy_fk.LeastSquaresFK`).
"""
from __future__ import annotations

import tempfile
import time
import xml.parsers.expat
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fkopt.errors import FkoptError
from fkopt.files import MAX_XML_DEPTH, read_text
from fkopt.mechanisms.urdf import MAX_URDF_BYTES
from fkopt.mechanisms.urdf_writer import chain_urdf
from fkopt.numerics.rotations import geodesic_angle
from fkopt.adapters.field.restarts import restart, SETTINGS


class NotApplicable(FkoptError):
    """The package cannot take this arm by design (EAIK on a 7-joint arm): the board shows a
    "not applicable: why" cell for it, never a zero; the message is the why."""


class FieldIK:
    """One outside IK solver on one arm; subclasses set ``name``, ``package``, ``settings``."""

    name = "?"
    package = "?"

    def __init__(self, arm, *, timeout: float, rng: np.random.Generator):
        self.arm, self.timeout, self.rng = arm, float(timeout), rng
        self.lo_rad, self.hi_rad = internal_bounds(arm)
        self.settings: dict[str, Any] = {"timeout_s": self.timeout}

    def random_start(self) -> np.ndarray:
        """Joints (rad, m) uniform inside the limits, from the wrapper's generator."""
        return self.lo_rad + self.rng.random(self.arm.dof) * (self.hi_rad - self.lo_rad)

    def public(self, q_internal) -> np.ndarray:
        """Joints (rad, m) -> fkopt's public units (deg, m); continuous joints wrapped into
        [-180, 180) as fkopt.inverse does."""
        q = np.asarray(q_internal, dtype=float) / self.arm._to_si
        per = self.arm.periodic_mask()
        q[per] = (q[per] + 180.0) % 360.0 - 180.0
        return q

    def solve1(self, T: np.ndarray) -> tuple[np.ndarray | None, bool]:
        raise NotImplementedError


@dataclass(frozen=True)
class ArmURDF:
    """The URDF a field package reads for an arm: its text, the chain's base and tip links, the
    moving joints (fkopt's unknowns, in order) and where the text came from (for messages and
    ``settings["urdf"]``)."""
    text: str
    base_link: str
    tip_link: str
    joint_names: tuple[str, ...]
    source: str

    @contextmanager
    def as_file(self, text: str | None = None):
        """The URDF (or ``text``, an edited copy of it) as a file for a package that reads only
        paths (rtb, ikpy): in a temporary folder of its own, removed when the block ends, so
        nothing is written beside the robot's files or into the results."""
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "chain.urdf"
            path.write_text(self.text if text is None else text, encoding="utf-8")
            yield path

    @classmethod
    def from_file(cls, path, base_link: str, tip_link: str, joint_names: tuple[str, ...] = ()) -> "ArmURDF":
        """A URDF file as it stands, for files fkopt did not take from a user (example-robot-data's
        robots in ``fkopt bench``): read bounded and refused with one line unless
        :func:`check_expression_free` proves nothing in it would be evaluated."""
        text = read_text(path, MAX_URDF_BYTES, field="urdf geometry.file")
        check_expression_free(text, str(path))
        return cls(text, base_link, tip_link, tuple(joint_names), str(path))


#: What xacro (run by roboticstoolbox on every file it reads) would evaluate: ``${expr}`` and
#: ``$(substitution)`` in attribute values and text.
_EXPRESSION = ("${", "$(")


def check_expression_free(text: str, where: str) -> None:
    """Refuse (one line naming ``where``) a URDF text holding anything xacro would act on, read as
    xacro reads it (qualified names kept, entities decoded: ``&#36;{`` is ``${`` to xacro, and
    nesting bounded like :func:`fkopt.files.parse_xml`): an element or attribute with the
    ``xacro:`` prefix (macros, includes, properties), or ``${`` or ``$(`` in any attribute value
    or text. A namespace declaration alone (``xmlns:xacro`` on ``<robot>``, as most of
    example-robot-data's files have) holds nothing to act on and passes."""
    parser = xml.parsers.expat.ParserCreate()          # no namespace processing: names as xacro sees them
    depth = 0

    def refuse(why):
        raise FkoptError(f"{where}: {why}; fkopt hands outside packages no file holding what they would "
                         "evaluate or include")

    def start(name, attrs):
        nonlocal depth
        depth += 1
        if depth > MAX_XML_DEPTH:
            refuse(f"elements nested deeper than {MAX_XML_DEPTH} levels")
        if name.lower().startswith("xacro:"):
            refuse(f"<{name[:40]}> is a xacro element")
        for key, value in attrs.items():
            if key.lower().startswith("xacro:"):
                refuse(f"<{name[:40]} {key[:40]}> is a xacro attribute")
            if any(x in value for x in _EXPRESSION):
                refuse(f"<{name[:40]} {key[:40]}> holds '${{' or '$('")

    def end(name):
        nonlocal depth
        depth -= 1

    text_parts: list[str] = []
    parser.StartElementHandler, parser.EndElementHandler = start, end
    parser.CharacterDataHandler = text_parts.append
    try:
        parser.Parse(text, True)
    except xml.parsers.expat.ExpatError as err:
        raise FkoptError(f"{where}: malformed URDF ({err})") from None
    # text is checked joined: expat may hand one text node over in pieces
    if any(x in "".join(text_parts) for x in _EXPRESSION):
        refuse("its text holds '${' or '$('")


def arm_urdf(arm) -> ArmURDF:
    """The URDF an outside package reads for ``arm`` (a URDF or MJCF arm, a DH table, with or
    without a tool frame): the one written from fkopt's own parsed chain
    (:func:`fkopt.mechanisms.urdf_writer.chain_urdf`, names made safe, FK-checked against MuJoCo
    in tests/test_urdf_writer.py), never the robot's own file (module docstring); checked once
    more by :func:`check_expression_free` before any package sees it."""
    w = chain_urdf(arm)
    source = f"written from fkopt's chain of {getattr(arm, 'path', arm.name)}"
    check_expression_free(w.text, source)
    return ArmURDF(w.text, w.base_link, w.tip_link, w.joint_names, source)


def internal_bounds(arm) -> tuple[np.ndarray, np.ndarray]:
    """The arm's joint limits in SI units (rad, m)."""
    return arm.bounds[:, 0] * arm._to_si, arm.bounds[:, 1] * arm._to_si


@dataclass
class IKAnswers:
    """Every answer of one solver on one arm: joints (n, dof) in public units (NaN: no answer),
    wall time per query (s), and what the solver claimed (never counted)."""
    solver: str
    joints: np.ndarray
    seconds: np.ndarray
    claimed: np.ndarray
    settings: dict = field(default_factory=dict)


def timed1(solver: FieldIK, T: np.ndarray) -> tuple[np.ndarray, float, bool]:
    """One query: joints (NaN when none), wall time (s), the solver's claim."""
    t0 = time.perf_counter()
    q, claimed = solver.solve1(T)
    dt = time.perf_counter() - t0
    return (np.full(solver.arm.dof, np.nan) if q is None else q), dt, bool(claimed)


def solve(solver: FieldIK, targets: np.ndarray) -> IKAnswers:
    """Every target (n, 4, 4) through ``solver``, one timed call per query."""
    n = len(targets)
    joints, secs, claimed = np.empty((n, solver.arm.dof)), np.empty(n), np.zeros(n, bool)
    for i in range(n):
        joints[i], secs[i], claimed[i] = timed1(solver, targets[i])
    return IKAnswers(solver.name, joints, secs, claimed, dict(solver.settings))


def pose_errors_rad(arm, q_public: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Position error (m) and geodesic rotation error (rad) of rows q (k, dof) against one
    target T, from fkopt's FK: shape (k, 2)."""
    F = arm.fk_matrix(q_public)
    pe = np.linalg.norm(F[:, :3, 3] - T[:3, 3], axis=-1)
    re = geodesic_angle(soa(F[:, :3, :3]), soa(np.broadcast_to(T[:3, :3], (len(F), 3, 3))))
    return np.stack([pe, re], axis=-1)


def soa(R: np.ndarray):
    """A (..., 3, 3) stack as :data:`fkopt.numerics.rotations.Matrix` (nested tuples of arrays)."""
    return tuple(tuple(R[..., i, j] for j in range(3)) for i in range(3))


class BlackBoxIK(FieldIK):
    """A black-box optimiser on :func:`pose_objective` (fkopt's FK as the black box), in the
    board's one restart loop (:func:`fkopt.adapters.field.restarts.restart`): random in-limit
    starts until the objective is below ``FTARGET`` or the wall-clock ``timeout`` has passed;
    subclasses supply :meth:`search` (one start, stopping by itself at the deadline). FTARGET =
    RUNG^2 = 1e-10 (m^2 + rad^2) implies both errors within the board's rung of 1e-5 (m, rad),
    the stopping test of every entry (docs/kinbench.md)."""

    FTARGET = 1e-10

    def __init__(self, arm, *, timeout, rng):
        super().__init__(arm, timeout=timeout, rng=rng)
        self.settings.update(SETTINGS, objective="|dp|^2 (m^2) + angle^2 (rad^2) on fkopt's FK", ftarget=self.FTARGET)

    def search(self, f, x0: np.ndarray, deadline: float) -> tuple[np.ndarray, float]:
        raise NotImplementedError

    def solve1(self, T):
        f = pose_objective(self.arm, T)

        def one(x0, deadline):
            x, fx = self.search(f, x0, deadline)
            return np.clip(x, self.lo_rad, self.hi_rad), fx, bool(fx <= self.FTARGET)
        x, ok, _ = restart(one, self.random_start, self.timeout)
        return self.public(x), ok


def pose_objective(arm, T: np.ndarray):
    """Black-box IK objective of rows of internal joints (k, dof): |dp|^2 (m^2) + angle^2
    (rad^2), 1 rad weighted as 1 m (the arms' reach is about a metre). Returns f (k,)."""
    def f(X):
        X = np.atleast_2d(np.asarray(X, dtype=float))
        e = pose_errors_rad(arm, X / arm._to_si, T)
        return e[:, 0] ** 2 + e[:, 1] ** 2
    return f
