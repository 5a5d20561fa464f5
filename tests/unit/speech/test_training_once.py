"""A model wanted by several processes at once (the robots of a first `vahr up`) is trained
once: the others wait for the first and read what it cached."""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from vahr.speech import text_classifier

if TYPE_CHECKING:
    from pathlib import Path

    import pytest

TEXTS = ["it is sunny", "sunny today", "the sun shines", "it rains", "rain today", "it pours"] * 3
LABELS = ["sunny", "sunny", "sunny", "rainy", "rainy", "rainy"] * 3


def _words(text: str) -> list[str]:
    return text.split()


def test_three_at_once_train_once_and_agree(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    fitted: list[int] = []
    real_fit = text_classifier.fit

    def counting_fit(*args: Any) -> Any:
        fitted.append(1)
        return real_fit(*args)

    monkeypatch.setattr(text_classifier, "fit", counting_fit)
    results: list[tuple[Any, bool]] = []

    def want() -> None:
        results.append(
            text_classifier.load_or_train(
                TEXTS, LABELS, _words, name="weather", recipe="words", cache_dir=tmp_path
            )
        )

    threads = [threading.Thread(target=want) for _ in range(3)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(60)
    assert len(results) == 3
    assert fitted == [1]
    assert sorted(cached for _, cached in results) == [False, True, True]
    assert {classifier.scores("sunny day").best[0] for classifier, _ in results} == {"sunny"}
