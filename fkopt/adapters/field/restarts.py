"""The restart loop of kinbench's board, for every outside entry whose package has none of its
own (fkopt's one restart loop, :func:`fkopt.numerics.restart_loop.restart`, with a deadline): pinocchio's CLIK (``pin-clik``), ikpy, pink and the black-box optimisers (cma-es,
scipy-lbfgsb, nevergrad-ngopt). TRAC-IK, optik and roboticstoolbox restart inside their own
calls and keep their own loops; EAIK is analytic; fkopt.inverse is the organiser's.

The loop (:func:`restart`): draw a start uniform inside the joint limits from the wrapper's
generator (no global RNG), run the package's local search from it, keep the best answer by its
error, and start again until an answer meets the entry's own stopping test or the query's
wall-clock timeout has passed. The deadline is checked between starts and handed to the search,
so a search the wrapper drives step by step (CLIK, pink) stops within a step of it; a package
call that cannot be interrupted (one ikpy or scipy run) is counted in full, as the clock track
counts any late answer as a failure at the timeout.

Every entry's stopping test implies the board's rung of 1e-5 m and 1e-5 rad
(:data:`RUNG`; the other rungs are read from the same answers): :func:`pose_error` is the test of
the entries whose package has none (ikpy, pink), on the package's own FK.

A search the wrapper drives step by step gives up on its start when it stalls
(:class:`Stall`): its error has not halved in :data:`STALL_WINDOW` steps (a start stuck at a joint
limit or in a local minimum; pinocchio's CLIK example, run from a random start, ends stuck at a
limit on 97-100 % of its failed starts), or after ``it_max`` steps.
"""
from __future__ import annotations

import time
from typing import Callable

import numpy as np

from fkopt.numerics.restart_loop import restart as one_loop

#: The board's rung (m, rad): every entry's stopping test implies it (docs/kinbench.md).
RUNG = 1e-5
#: A stepped search restarts when its error has not halved within this many steps.
STALL_WINDOW = 10
STALL_RATIO = 0.5


class Stall:
    """Whether a stepped search has stalled: its error has not fallen below ``STALL_RATIO`` times
    its value ``STALL_WINDOW`` steps ago."""

    def __init__(self):
        self.errors: list[float] = []

    def __call__(self, error: float) -> bool:
        self.errors.append(float(error))
        return len(self.errors) > STALL_WINDOW and self.errors[-1] > STALL_RATIO * self.errors[-1 - STALL_WINDOW]


def restart(search: Callable[[np.ndarray, float], tuple[np.ndarray, float, bool]],
            start: Callable[[], np.ndarray], timeout: float) -> tuple[np.ndarray, bool, int]:
    """The restart loop (:func:`fkopt.numerics.restart_loop.restart`): ``search(x0, deadline)`` -> (answer, error, met its stopping test) from
    starts ``start()`` until one meets its test or ``timeout`` (s) has passed. Returns the best
    answer (the met one, else the smallest error), whether it met the test, and the number of
    starts."""
    deadline = time.perf_counter() + timeout
    (x, _, _), ok, starts = one_loop(lambda j: start(), lambda x0: search(x0, deadline), lambda got: got[2],
                                     merit=lambda got: got[1], give_up=lambda: time.perf_counter() > deadline)
    return x, ok, starts


def pose_error(F: np.ndarray, T: np.ndarray) -> tuple[float, float]:
    """(position error (m), geodesic rotation angle (rad)) of frame F against target T (4x4):
    the angle from the chordal distance, 2 asin(|R_F - R_T|_F / (2 sqrt 2)), exact and stable
    at small angles (arccos of the trace is not)."""
    chord = np.linalg.norm(F[:3, :3] - T[:3, :3])
    return float(np.linalg.norm(F[:3, 3] - T[:3, 3])), float(2 * np.arcsin(min(1.0, chord / (2 * np.sqrt(2)))))


def within_rung(F: np.ndarray, T: np.ndarray, rung: float = RUNG) -> bool:
    """The stopping test of the entries whose package has none: both errors within the rung."""
    p, r = pose_error(F, T)
    return p <= rung and r <= rung


SETTINGS = {"restarts": "fkopt/adapters/field/restarts.py: starts uniform in the limits (wrapper's generator) until "
                        "the entry's stopping test holds or the timeout has passed",
            "wall_clock_limit": True}
