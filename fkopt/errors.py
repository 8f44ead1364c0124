"""User-facing errors.

Every mistake a user can make (bad YAML, unknown names, out-of-range settings, unreachable
targets) raises :class:`FkoptError` with a one-line message that names the file/field and the
allowed values. The CLI prints it as ``fkopt: error: <message>`` and exits with status 2;
anything else escaping is a bug in fkopt.
"""


class FkoptError(Exception):
    """A one-line, user-facing error (bad input, not a bug)."""


def did_you_mean(value: str, allowed) -> str:
    """``"unknown 'x'; allowed: a, b, c"`` helper text listing the allowed values."""
    return ", ".join(sorted(str(a) for a in allowed))
