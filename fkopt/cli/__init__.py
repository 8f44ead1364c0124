"""The ``fkopt`` command line: a thin layer over the Python API and the engine. Each command
parses its options, calls one library function and prints; every user mistake ends as one line
``fkopt: error: ...`` on stderr and exit status 2, Ctrl-C with status 130, neither with a traceback.

* :mod:`.entry_point` -- the typer ``app``, ``--version``, :func:`main` (the ``fkopt`` program)
* :mod:`.arguments` -- ``name=value`` options, ``--geometry``, a serial arm's ``--pose``
* :mod:`.listing` -- ``fkopt list``
* :mod:`.ik_fk` -- ``fkopt ik``, ``fkopt fk``
* :mod:`.running` -- ``fkopt run``, ``study``, ``suite``, ``schema``; :mod:`.display` -- their progress
  and summary tables
* :mod:`.tools` -- ``fkopt export``, ``fkopt bench``
* :mod:`.stored` -- ``fkopt reproduce``, ``report``, ``pages``, ``check``

Start-up: every command module is imported to build the command table, so each imports at its
top only what every command needs (typer, numpy, the registry, fkopt.files); rich, the engine,
the kinds, the solvers, reproduce, bench and export are imported inside the commands that use
them (docs/design.md, "Start-up", has the measured import times).
"""
from __future__ import annotations

# importing the command modules registers their commands on ``app``, in the order --help lists them
from fkopt.cli import listing, running, ik_fk, tools, stored  # noqa: F401, E401
from fkopt.cli.entry_point import app, main, reflow_help

reflow_help()

__all__ = ["app", "main"]
