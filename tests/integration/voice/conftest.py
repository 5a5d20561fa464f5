"""Shared voice fixtures: one offline recognizer per session (its decoder loads in ~0.1 s)."""

from __future__ import annotations

import pytest

from robot_agent.voice.hearing import Hearing, offline_hearing


@pytest.fixture(scope="session")
def hearing() -> Hearing:
    return offline_hearing()
