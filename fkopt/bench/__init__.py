"""``fkopt bench``: fkopt's speed on this machine, peers side by side, as ratios (floor 5).

:mod:`.sections` -- the sections and the table; :mod:`.ik` -- the IK sections beside
roboticstoolbox; ``ref/`` -- the C reference loop of the ``cases`` section."""
