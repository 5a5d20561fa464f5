"""`vahr console --speak` hears each new announcement once, and none from before it started."""

from __future__ import annotations

from typing import Any

from vahr.plumbing.announcement_feed import AnnouncementFeed


def test_only_announcements_made_after_the_start_are_handed_over_once() -> None:
    # Given a system that already announced one thing
    history: list[dict[str, Any]] = [
        {"id": "vahr~offline~1", "speech": "Placebot two has gone offline."}
    ]

    def fetch(api: str, method: str, path: str) -> dict[str, Any]:
        assert (api, method, path) == ("http://api", "GET", "/vahr/announcements")
        return {"announcements": list(history)}

    heard: list[str] = []
    feed = AnnouncementFeed("http://api", lambda a: heard.append(a["speech"]), fetch=fetch)
    feed.start()
    try:
        # When a robot gets stuck, and the feed polls twice
        history.append({"id": "vahr~stuck~2", "speech": "Placebot one is stuck."})
        feed.poll()
        feed.poll()
    finally:
        feed.stop()
    # Then the new announcement is heard once, the old one not at all
    assert heard == ["Placebot one is stuck."]
