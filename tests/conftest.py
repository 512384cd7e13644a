"""Markers for the whole suite: a test that uses the ``xvfb`` or ``offscreen`` fixture (tests/viewer/
conftest.py) is a ``window`` test without saying so; ``slow`` ones say so themselves.

Under pytest-xdist (``make test``: ``-n auto --dist loadgroup``) the tests of a module that runs its
window scenarios as one batch (a module-level ``BATCH``: tests/viewer/conftest.py's ``run_driver``)
share one worker, so the batch runs once, not once on every worker its tests land on. So do the tests
of a module that use one of the costly module-scoped fixtures it names in ``SHARED`` (a scene run, a
pile settled first), so the fixture is made once."""

from __future__ import annotations

import signal

import pytest

# A suite started in the background by a script (`make test &`, nohup) inherits SIGINT ignored, and so
# would every process a test starts: the Ctrl+C tests need it delivered. A Python handler (unlike
# SIG_IGN) goes back to the default in the children.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

WINDOW_FIXTURES = frozenset({"xvfb", "offscreen", "offscreen_session"})


@pytest.hookimpl(tryfirst=True)  # before xdist's loadgroup reads the groups
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if WINDOW_FIXTURES.intersection(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.window)
        module = getattr(item, "module", None)
        shared = set(getattr(module, "SHARED", ())).intersection(getattr(item, "fixturenames", ()))
        if getattr(module, "BATCH", None) or shared:
            item.add_marker(pytest.mark.xdist_group(module.__name__))
