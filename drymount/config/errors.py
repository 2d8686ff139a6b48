"""The configuration's error type, importable without NumPy (the command line catches
it around every command)."""

from __future__ import annotations

__all__ = ["ConfigError"]


class ConfigError(ValueError):
    """An invalid configuration. ``problems`` lists every problem found.

    Each problem names the field path (``mounts[2].axial.friction.kf``; indices of
    ``[[mounts]]`` count from 0), the value found and what is allowed. ``str()`` gives
    a message with one problem per line, meant to be printed as is.
    """

    def __init__(self, problems: list[str], source: str | None = None):
        self.problems = list(problems)
        self.source = source
        super().__init__(self._message())

    def _message(self) -> str:
        n = len(self.problems)
        where = f" {self.source}" if self.source else ""
        head = f"invalid configuration{where}: {n} problem{'s' if n != 1 else ''}"
        return "\n".join([head + ":"] + [f"  - {p}" for p in self.problems])
