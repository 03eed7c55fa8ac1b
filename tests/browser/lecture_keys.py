"""Stepping through lecture mode as an instructor does: lecture.js queues each key press behind
the fitting of the equations it shows, and counts those still to run on <html data-lecture-busy>."""

from __future__ import annotations

LECTURE_IDLE = "() => (document.documentElement.dataset.lectureBusy || '0') === '0'"


def press(p, key: str) -> None:
    """A key, then wait until the page has done what it asked."""
    p.keyboard.press(key)
    p.wait_for_function(LECTURE_IDLE)


def reveal_all(p) -> None:
    """→ until every step is shown (a step taller than the screen takes a press per screen)."""
    n = p.locator("#steps > .step").count()
    for _ in range(20 * n):
        if p.get_attribute("#steps", "data-revealed") == str(n):
            return
        press(p, "ArrowRight")
    raise AssertionError(f"{n} steps not revealed by → after {20 * n} presses")
