"""``fkopt bench``: fkopt's speed on this machine, peers side by side, as ratios (floor 5).

:mod:`.sections` -- runs the sections and writes the table; one module per section (listed
there); :mod:`.measuring` -- the rows and timers they share; ``ref/`` -- the C reference loop of
the ``cases`` and ``swarms`` sections (:mod:`.c_reference`)."""
