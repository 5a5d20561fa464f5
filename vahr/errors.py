"""The error a user can act on: command-line tools print it as one line and exit non-zero."""

from __future__ import annotations


class VahrError(Exception):
    """A failure with a message meant for the person at the terminal (no traceback)."""
