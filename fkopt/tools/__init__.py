"""Tools over stored results and over fkopt itself (floor 5): :mod:`.export` (``fkopt export``:
IOHprofiler files, written by :mod:`fkopt.run.iohformat` from each kind's loader),
:mod:`.peers` (the peer experiments' summary, ``python -m fkopt.tools.peers``) and :mod:`.bench`
(``fkopt bench``: fkopt's speed on this machine, one module per section)."""
