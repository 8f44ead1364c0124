"""The typer application every command registers on, its global options (``--version``), the
state Ctrl-C reads (:data:`INTERRUPTED`) and :func:`main`, the entry point: every user mistake
ends as one line ``fkopt: error: ...`` on stderr and exit status 2, Ctrl-C with status 130,
neither with a traceback."""
from __future__ import annotations

import functools
import inspect
import signal
import sys
import threading
from pathlib import Path

import typer

import fkopt
from fkopt.errors import FkoptError
from fkopt.files import one_line
from fkopt.numerics.path import version_line

try:
    from typer.core import TyperOption
except ImportError:           # an older typer has neither the type tags nor this class
    TyperOption = None

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="Rerunnable swarm-optimisation experiments for robot mechanism kinematics. "
                       "Start with: fkopt run configs/mao2017/tab2_tab3_fig2.yaml (writes "
                       "./fkopt-results/); the files and commands are described in README.md and docs/.")

#: Where ``fkopt run`` and ``fkopt study`` write unless given ``--out``: a git-ignored folder of the
#: current directory, so a user's own experiment never lands in the tracked ``results/`` (which
#: ``fkopt reproduce`` and ``fkopt check`` use) without asking for it with ``--out results``.
DEFAULT_OUT = Path("fkopt-results")


def _flags_without_type_tag() -> None:
    """typer (>= 0.2x) tags every option with its type in ``--help``, flags too (``--json <bool>``);
    a flag takes no value, so its tag only misleads. Options with a value keep theirs."""
    shown = getattr(TyperOption, "display_type_rich", None)
    if shown is None or getattr(shown, "_fkopt", False):
        return

    def display_type_rich(self, ctx):
        return None if getattr(self, "is_flag", False) else shown(self, ctx)
    display_type_rich._fkopt = True
    TyperOption.display_type_rich = display_type_rich


def _version(value: bool) -> None:
    if value:
        typer.echo(f"fkopt {fkopt.__version__}; {version_line()}")
        raise typer.Exit()


@app.callback()
def _main_options(version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                               help="print fkopt's version and exit")):
    """Rerunnable swarm-optimisation experiments for robot mechanism kinematics."""


_flags_without_type_tag()


def console(stderr: bool = False):
    """The console every command prints tables and progress to (rich is imported here, not at start-up:
    ``fkopt ik --json`` and ``fkopt fk`` print no table; docs/design.md, "Start-up")."""
    from rich.console import Console
    return Console(stderr=stderr, highlight=False)


#: What Ctrl-C ends and how to continue it: set while a config runs, printed by :func:`main`.
INTERRUPTED = {"hint": None}


def reflow_help() -> None:
    """typer's rich help keeps the line breaks of a docstring's later paragraphs, so a paragraph
    wrapped at 100 source columns broke mid-sentence in an 80-column terminal: each command's help
    is its docstring with every paragraph on one line, for the terminal to wrap. Called once every
    command is registered (:mod:`fkopt.cli`)."""
    for info in app.registered_commands:
        if info.help is None and info.callback is not None and info.callback.__doc__:
            paragraphs = inspect.cleandoc(info.callback.__doc__).split("\n\n")
            info.help = "\n\n".join(" ".join(p.split()) for p in paragraphs)


def exit_interrupted(message: str) -> None:
    """Print ``message`` and exit with status 130 (Ctrl-C handled), never by the signal itself.

    CPython (3.11) marks a KeyboardInterrupt raised inside ``exec``/``eval`` of a *string*
    (numba, dataclasses and namedtuple build code that way while a run starts) as unhandled in
    ``run_eval_code_obj``, and that mark survives our ``except``: the interpreter then ends by
    re-raising SIGINT (status -2) after printing our line. The mark is cleared at the start of the
    next string ``exec``, so one empty ``exec`` forgets it (tests/test_hostile.py sends SIGINT
    inside such an ``exec``; CI once saw -2 from a real run interrupted at that moment)."""
    print(message, file=sys.stderr)
    exec("pass")   # noqa: S102 -- a constant string: clears CPython's unhandled-interrupt mark
    sys.exit(130)


def interrupt_not_swallowed(args, otherwise=None) -> None:
    """``sys.unraisablehook`` while :func:`main` runs: a Ctrl-C that lands in a finaliser
    (``__del__``, e.g. llvmlite disposing a module) cannot propagate, so CPython printed
    "Exception ignored in ..." with a traceback and went on as if no key were pressed. The
    interrupt is sent to the main thread again instead, silently; any other unraisable exception
    goes to ``otherwise`` (the hook that was installed before, else Python's own).

    A short-lived daemon thread sends a real SIGINT (``_thread.interrupt_main`` only sets a flag,
    which a main thread blocked waiting for a worker's result would not see until the result came)
    a moment later: an interrupt raised inside this hook would be "ignored" in turn, and a second
    Ctrl-C that lands here is sent as well. While the interpreter shuts down nothing is sent (no
    thread can start then, and the process is ending anyway)."""
    if args.exc_type is None or not issubclass(args.exc_type, KeyboardInterrupt):
        (otherwise or sys.__unraisablehook__)(args)
        return
    if sys.is_finalizing() or not callable(signal.getsignal(signal.SIGINT)):   # ignored or fatal: nothing to redo
        return

    def send() -> None:
        signal.pthread_kill(threading.main_thread().ident, signal.SIGINT)

    def later() -> None:
        timer = threading.Timer(REDELIVERY_DELAY, send)
        timer.daemon = True          # a process on its way out does not wait for it
        timer.start()
    try:
        later()
    except KeyboardInterrupt:
        later()


#: Seconds between a finaliser's swallowed Ctrl-C and its delivery to the main thread again.
REDELIVERY_DELAY = 0.01


def main() -> None:
    """Entry point: user errors are one line and exit 2, drift exits 1, Ctrl-C exits 130. While it
    runs, a Ctrl-C swallowed by a finaliser is sent again (:func:`interrupt_not_swallowed`); the
    previous ``sys.unraisablehook`` is put back when it returns or exits (the tests call it in
    their own process)."""
    previous = sys.unraisablehook
    sys.unraisablehook = functools.partial(interrupt_not_swallowed, otherwise=previous)
    try:
        _main()
    finally:
        sys.unraisablehook = previous


def _main() -> None:
    def interrupted() -> str:
        hint = INTERRUPTED["hint"]
        return "fkopt: interrupted (previous results are kept" + (f"; {hint})" if hint else ")")

    def fail(message: str) -> None:
        print(f"fkopt: error: {one_line(message)}", file=sys.stderr)
        sys.exit(2)

    if not sys.argv[1:]:     # bare `fkopt`: the help, and success (nothing went wrong)
        sys.argv.append("--help")
    try:
        code = app(standalone_mode=False)
    except FkoptError as err:
        fail(str(err))
    except KeyboardInterrupt:
        exit_interrupted(interrupted())
    except MemoryError:
        fail("out of memory; reduce runs, population, iterations or cases")
    except RecursionError:
        fail("input nested too deeply")
    except OSError as err:   # the file system refused (disk full, permissions): not a bug of fkopt
        where = f"{err.filename}: " if err.filename else ""
        fail(f"{where}{err.strerror or err}")
    except Exception as err:  # click's usage errors (typer vendors click): no traceback either
        kind = type(err).__name__
        if kind == "Exit":
            sys.exit(getattr(err, "exit_code", 0))
        if kind == "Abort" and isinstance(err.__cause__, EOFError):   # click turns EOFError into Abort
            fail(f"unexpected end of a file (truncated input?): {err.__cause__ or 'EOFError'}")
        if kind == "Abort":
            exit_interrupted(interrupted())
        if callable(getattr(err, "format_message", None)):
            fail(f"{err.format_message()} (see fkopt --help)")
        raise
    if code == 130:   # typer (>= 0.12) turns Ctrl-C into a returned 130 when not standalone
        exit_interrupted(interrupted())
    if isinstance(code, int) and code:
        sys.exit(code)
