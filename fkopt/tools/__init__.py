"""Tools over stored results (floor 5): :mod:`.export` (``fkopt export``: IOHprofiler files),
:mod:`.iohformat` (the IOHprofiler format: constants and a reader), :mod:`.peers` (the peer
experiments' summary, ``python -m fkopt.tools.peers``)."""
