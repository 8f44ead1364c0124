"""One-line notices about the numerics path on stderr, each at most once per process (the
compiled path falling back to numpy, a compiled-code cache set aside or not writable)."""
from __future__ import annotations

import sys
import threading

_LOCK = threading.Lock()
_SAID: set[str] = set()


def notice(key: str, line: str) -> bool:
    """Print ``fkopt: <line>`` on stderr, once per process for each ``key``; True when printed."""
    with _LOCK:
        if key in _SAID:
            return False
        _SAID.add(key)
    print(f"fkopt: {line}", file=sys.stderr, flush=True)
    return True
