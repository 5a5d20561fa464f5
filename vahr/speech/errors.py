"""The one error the speech package raises."""

from __future__ import annotations


class SpeechError(Exception):
    """Speech could not be made, heard or carried (no TTS, unreadable audio, channel down);
    the message says why in words a user can act on."""
