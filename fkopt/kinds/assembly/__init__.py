"""``kind: assembly``: every real assembly mode of a parallel mechanism (:mod:`.kind`)."""
