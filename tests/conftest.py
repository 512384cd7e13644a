"""Markers for the whole suite: a test that uses the ``xvfb`` or ``offscreen`` fixture (tests/viewer/
conftest.py) is a ``window`` test without saying so; ``slow`` ones say so themselves."""

from __future__ import annotations

import pytest

WINDOW_FIXTURES = frozenset({"xvfb", "offscreen", "offscreen_session"})


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if WINDOW_FIXTURES.intersection(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.window)
