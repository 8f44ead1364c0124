"""What the commands that run configs print: a progress bar with the time left on a terminal, a
plain line every ~10 s otherwise (:class:`RunProgress`, :class:`Heartbeat`), and after each config
its summary table (:func:`print_outcome`), every value printed whole.

Every command imports this module at start-up, so what it needs only when it prints is imported
there (docs/design.md, "Start-up"): rich where a bar or table is drawn, the kinds' result classes
and summary tables (they pull pandas) in :func:`print_outcome`, when the run has loaded them already."""
from __future__ import annotations

import math
import time
from pathlib import Path



def _clock(seconds: float) -> str:
    seconds = int(round(seconds))
    return f"{seconds // 60}m{seconds % 60:02d}s" if seconds >= 60 else f"{seconds}s"


def _eta(done: float, total: float, elapsed: float) -> str:
    """Time left at the pace so far (finished work, counting the running task's fraction)."""
    if done <= 0 or done >= total:
        return "--" if done < total else "0s"
    return _clock(elapsed * (total - done) / done)


#: Seconds between plain progress lines when stdout is not a terminal.
HEARTBEAT_S = 10.0


class Heartbeat:
    """Plain progress lines for a stdout that is not a terminal (a log, CI, a pipe): one line at
    most every ``every`` seconds, so a long run shows it is alive without a bar's escape codes."""

    def __init__(self, con, every: float | None = None, quiet: bool = False):
        self.con, self.every, self.clock = con, HEARTBEAT_S if every is None else every, time.perf_counter
        self.start = self.last = self.clock()
        self.on = not (quiet or con.is_terminal)

    def beat(self, text) -> None:
        now = self.clock()
        if self.on and now - self.last >= self.every:
            self.last = now
            self.con.print(f"[{_clock(now - self.start)}] {text()}", highlight=False, markup=False)


class RunProgress:
    """Progress of one config's tasks as the runner's ``progress(label, done, total)`` callback
    (None when quiet): a rich bar with the time left on a terminal, a plain line every ~10 s
    otherwise. ``running`` hears the running task's fraction (fkopt.progress), so the bar and
    its time left move within a task too."""

    def __init__(self, con, name: str, total: int, quiet: bool):
        self.con, self.name, self.total, self.quiet = con, name, total, quiet

    def __enter__(self):
        if self.quiet:
            return None
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
        self.heart = Heartbeat(self.con)
        self.bar = Progress(TextColumn(f"[bold]{self.name}[/]"), BarColumn(), MofNCompleteColumn(),
                            TextColumn("{task.description}"), TimeElapsedColumn(),
                            TextColumn("{task.fields[left]} left"), console=self.con, transient=True,
                            disable=not self.con.is_terminal)
        self.bar.__enter__()
        self.task = self.bar.add_task("", total=self.total, left="--")
        return self

    def __call__(self, label: str, done: float, total: int) -> None:
        elapsed = self.heart.clock() - self.heart.start
        left = _eta(done, total, elapsed)
        self.bar.update(self.task, completed=done, description=label, left=left)
        self.heart.beat(lambda: f"{self.name}: {done:.1f}/{total} tasks ({label}), about {left} left")

    running = __call__

    def __exit__(self, *exc):
        if not self.quiet:
            self.bar.__exit__(*exc)
        return False


def print_outcome(con, outcome, tasks: int) -> None:
    """What is printed after a config ran: what its kind says (``Kind.console``: the summary table
    of an experiment or a study, the top of a suite's board) or its folder, and how many finished
    tasks a --resume reused."""
    from fkopt.run.kinds import config_kind  # lazy: the engine (executors, ~20 ms); loaded by the run already
    result = outcome.result
    shown = config_kind(result.config).console
    said = shown(result, outcome.folder) if shown is not None else None
    if hasattr(said, "columns"):                        # a summary table
        print_summary(con, said, outcome.folder, outcome.wall_s)
    else:
        head, *lines = said or [""]
        con.print(f"{outcome.folder}  ({outcome.wall_s:.2f} s){head}")
        for line in lines:
            con.print(line, markup=False, highlight=False, soft_wrap=True)
    reused = tasks - len(outcome.computed)
    if 0 < reused <= tasks:
        con.print(f"resumed: {reused} finished task(s) reused, {len(outcome.computed)} computed")


#: Column headers of the printed summary (summary.csv keeps the full names).
SHORT = {"median_fitness": "median f", "mean_fitness": "mean f", "std_fitness": "std f",
         "success_rate": "success", "median_iterations_to_threshold": "med. it→thr",
         "mean_evaluations": "mean evals"}


def summary_rows(df, cols: list[str]) -> tuple[list[list[str]], list[str]]:
    """The printed cells of a summary and the notes under it. Many cases (more than 8): one row
    per algorithm, its success the fraction of all runs (the mean of the cases' rates: every
    case has the same runs) and the other columns medians over the cases -- a median of the
    cases' success rates printed 0 beside a median iterations to the threshold of the few cases
    that reached it. A cell with no value (no run reached the threshold) is "-", not nan."""
    notes = []
    if df["case"].nunique() > 8:   # many cases: one line per algorithm
        cases = df["case"].nunique()
        how = {c: ("mean" if c == "success_rate" else "median") for c in cols[2:]}
        df = df.groupby("algorithm", sort=False).agg(how).reset_index()
        df.insert(0, "case", f"all {cases} cases")
        notes.append(f"over all {cases} cases: success is the fraction of all runs, the other columns "
                     "the median over the cases" + (" (med. it→thr: of the cases some run reached the "
                                                    "threshold in)" if "median_iterations_to_threshold" in cols else ""))
    rows = [["-" if isinstance(v, float) and math.isnan(v) else f"{v:.3g}" if isinstance(v, float) else str(v)
             for v in row[cols]] for _, row in df.iterrows()]
    if any("-" == cell for row in rows for cell in row[2:]):
        notes.append("-: no value (no run reached the threshold)")
    return rows, notes


def print_summary(con, df, folder: Path, wall: float) -> None:
    from rich.table import Table
    cols = [c for c in ("case", "algorithm", *SHORT) if c in df]
    rows, notes = summary_rows(df, cols)
    table = Table(title=f"{folder}  ({wall:.2f} s)")
    for j, c in enumerate(cols):
        # values are never cut ("1.54e-…", "succe…"): each column is as wide as its widest value
        # (headers may wrap); a terminal narrower than that wraps the lines, losing nothing
        widest = max((len(r[j]) for r in rows), default=1)
        table.add_column(SHORT.get(c, c), justify="right", no_wrap=True, min_width=widest)
    for r in rows:
        table.add_row(*r)
    print_wide(con, table)
    for note in notes:
        con.print(note, markup=False, highlight=False)


def print_wide(con, renderable) -> None:
    """Print ``renderable`` unclipped: in a pipe (no terminal, where rich assumes 80 columns)
    or a narrow terminal the console is widened to what the table needs."""
    from rich.console import Console
    from rich.measure import Measurement
    need = Measurement.get(con, con.options.update_width(10_000), renderable).maximum
    if need > con.width:
        con = Console(width=need, highlight=False, file=con.file, force_terminal=con.is_terminal)
    con.print(renderable)
