"""Shared voice fixtures: one offline recognizer per session (its decoder loads in ~0.1 s)."""

from __future__ import annotations

import pytest

from robot_agent.voice.understanding import Understanding, offline_understanding


@pytest.fixture(scope="session")
def understanding() -> Understanding:
    return offline_understanding()
