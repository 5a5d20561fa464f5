"""Real headless Chromium for the station's tests and benchmarks (Debian's `chromium`,
driven by Playwright, which cannot download browsers here).

`launch(playwright, microphone=FILE)` starts it with a fake microphone that plays FILE (a
16 kHz mono WAV) from its start each time the page opens the microphone, once (`%noloop`);
tests overwrite FILE between presses. `Watch` collects what must never happen on a page:
console errors and warnings, uncaught exceptions, failed requests and error responses.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pathlib import Path

    from playwright.sync_api import Browser, Page, Playwright

CHROMIUM = "/usr/bin/chromium"
ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--use-fake-device-for-media-stream",
    "--use-fake-ui-for-media-stream",
    # The reply is played without the page having been clicked first (a key press is not a
    # gesture in every case Chromium counts).
    "--autoplay-policy=no-user-gesture-required",
]


def launch(
    playwright: Playwright, *, microphone: Path | None = None, extra: tuple[str, ...] = ()
) -> Browser:
    args = list(ARGS)
    if microphone is not None:
        args.append(f"--use-file-for-fake-audio-capture={microphone}%noloop")
    return playwright.chromium.launch(executable_path=CHROMIUM, args=[*args, *extra])


class Watch:
    """Everything a page did wrong while watched."""

    def __init__(self, page: Page) -> None:
        self.problems: list[str] = []
        self.requests: list[str] = []
        page.on("console", self._console)
        page.on("pageerror", lambda error: self.problems.append(f"page error: {error}"))
        page.on("requestfailed", self._failed)
        page.on("response", self._response)
        page.on("request", lambda request: self.requests.append(request.url))

    def _console(self, message: object) -> None:
        kind = getattr(message, "type", "")
        if kind in ("error", "warning"):
            self.problems.append(f"console {kind}: {getattr(message, 'text', '')}")

    def _failed(self, request: object) -> None:
        url = getattr(request, "url", "")
        failure = getattr(request, "failure", None)
        # A stream cut when the page closes is not a failed request.
        if failure and "ERR_ABORTED" in str(failure) and url.endswith("/api/stream"):
            return
        self.problems.append(f"request failed: {url} ({failure})")

    def _response(self, response: object) -> None:
        status = getattr(response, "status", 200)
        if status >= 400:
            self.problems.append(f"HTTP {status}: {getattr(response, 'url', '')}")
