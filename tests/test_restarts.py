"""The one restart loop (fkopt/numerics/restart_loop.py): its rules, and that the solvers that hand it
their search give the answers they gave with their own loops."""
import math

import numpy as np

from fkopt.numerics.restart_loop import restart, restart_rows


def test_stops_at_the_first_answer_that_meets_the_test():
    seen = []
    got, met, used = restart(lambda j: j, lambda x: seen.append(x) or 10 - x, lambda a: a <= 7, merit=float)
    assert (got, met, used) == (7, True, 4) and seen == [0, 1, 2, 3]


def test_keeps_the_smallest_merit_earliest_on_ties_within_the_budget():
    merits = [5.0, 2.0, 3.0, 2.0]
    got, met, used = restart(lambda j: j, lambda j: j, lambda a: False, merit=lambda j: merits[j], budget=4)
    assert (got, met, used) == (1, False, 4)


def test_the_first_answer_is_kept_whatever_its_merit():
    """A merit that is not a number counts as infinite: a later finite one replaces it, and when
    none is finite the first answer stands (there is always one)."""
    merits = [math.nan, math.inf, 4.0]
    assert restart(lambda j: j, lambda j: j, lambda a: False, merit=lambda j: merits[j], budget=3)[0] == 2
    assert restart(lambda j: j, lambda j: j, lambda a: False, merit=lambda j: math.nan, budget=3)[0] == 0


def test_give_up_is_checked_after_each_start_so_one_start_always_runs():
    calls = []
    got, met, used = restart(lambda j: j, lambda j: calls.append(j) or j, lambda a: False, merit=float,
                             give_up=lambda: True)
    assert (got, met, used) == (0, False, 1) and calls == [0]
    assert restart(lambda j: j, lambda j: j, lambda a: False, budget=0) == (None, False, 0)


def test_rows_leave_when_done_and_the_loop_ends_without_rows_or_starts():
    rows = np.arange(6)
    ran = []

    def search(j, r):
        ran.append((j, r.tolist()))
        return None if j == 3 else (r % 3 == j)
    left = restart_rows(rows, search)
    assert ran == [(0, [0, 1, 2, 3, 4, 5]), (1, [1, 2, 4, 5]), (2, [2, 5])]
    assert left.tolist() == []
    assert restart_rows(rows, lambda j, r: None).tolist() == rows.tolist()


def test_field_restart_is_the_one_loop_with_a_deadline():
    from fkopt.adapters.field.restarts import restart as field_restart
    errors = iter([3.0, 1.0, 2.0, 0.0])
    x, ok, n = field_restart(lambda x0, deadline: (x0, next(errors), False), lambda: np.zeros(1), timeout=0.0)
    assert not ok and n == 1                       # past the deadline after the first start
    errors = iter([3.0, 1.0, 2.0, 0.5])
    starts = iter(range(10))
    x, ok, n = field_restart(lambda x0, deadline: (x0, (e := next(errors)), e < 1.0), lambda: np.array([next(starts)]),
                             timeout=10.0)
    assert ok and n == 4 and x[0] == 3
