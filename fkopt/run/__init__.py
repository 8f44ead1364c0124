"""The engine (floor 3 of docs/design.md): every kind of config runs through it, and it imports no kind.

config -> :mod:`.pipeline` (load, validate/plan, output folder, run, write, rerun) -> :mod:`.tasks`
(plan of tasks, task files, resume) -> :mod:`.executors` (this process, processes, Dask) -> the
kind's merge -> :mod:`.writers` (every output file; ``meta.json``, ``env.json``) -> :mod:`.compare`
(``fkopt check``'s comparison rules).

Shared pieces: :mod:`.config_base` (the config models every kind shares), :mod:`.solving` (one solve
path: mechanism, problem, seeds, :func:`fkopt.solve`), :mod:`.memory` (the memory estimate's
refusal), :mod:`.record` (the one run record), :mod:`.timing`, :mod:`.trace`, :mod:`.plotting`,
:mod:`.provenance` (``env.json``), :mod:`.config_reference` (the config files' reference).
"""
