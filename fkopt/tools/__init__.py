"""Tools over stored results and over fkopt itself (floor 5): :mod:`.export` (``fkopt export``:
IOHprofiler files), :mod:`.iohformat` (the IOHprofiler format: constants and a reader),
:mod:`.peers` (the peer experiments' summary, ``python -m fkopt.tools.peers``) and :mod:`.bench`
(``fkopt bench``: fkopt's speed on this machine, one module per section)."""
