# Two commands do all the set-up: `make demo` opens the viewer, `make test` runs the checks.
# `make check` is the inner loop: lint, format and the tests marked neither slow nor window, on every core (< 1 min);
# `make test` runs every test on every core (pytest-xdist; a window batch keeps to one worker, tests/conftest.py).
# demo installs what ballpit itself needs and PyAV (F9 records MP4); test adds the test tools (pytest, ruff,
# scipy, ...).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
PYTEST_ARGS ?=  # more for pytest: make test PYTEST_ARGS=--durations=20
# The tests start some 200 Python processes (window drivers, command lines, children), each importing
# NumPy and ballpit, most of them pyglet too. Where the environment says PYTHONDONTWRITEBYTECODE (this
# machine's does), every one of them compiled those modules from source again, and each pytest process
# rewrote every test module's asserts again: about 0.2 CPU-s a process. The tests write the bytecode,
# under .venv/pycache (out of the source tree; make clean removes it).
PYTEST_ENV := PYTHONDONTWRITEBYTECODE= PYTHONPYCACHEPREFIX=$(CURDIR)/$(VENV)/pycache

.PHONY: demo check test lint format bench clean

# The installs go through uv (from PyPI, into the venv): it links the wheels from its cache instead of
# unpacking them, and compiles no bytecode (the tests compile what they import, PYTEST_ENV above).
# From a clone, with the caches warm: the test install 10 s instead of pip's 19-27 (its 330 MB of
# PyBullet data alone took pip several seconds). Where uv cannot be had, pip does the same install.
INSTALL = $(PY) -m pip install --quiet uv && $(VENV)/bin/uv pip install --quiet --python $(PY) -e
PIP_INSTALL = $(PY) -m pip install --quiet --no-compile -e

$(VENV)/.ballpit: pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(INSTALL) '.[video]' || $(PIP_INSTALL) '.[video]'
	touch $@

# one install for both sets (a second resolve and editable build cost make test seconds from a clone)
$(VENV)/.installed: pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(INSTALL) '.[video,test]' || $(PIP_INSTALL) '.[video,test]'
	touch $(VENV)/.ballpit $@

# With no display the viewer prints how to render offscreen instead; that is not a failure here.
demo: $(VENV)/.ballpit
	@$(VENV)/bin/ballpit || { status=$$?; [ -z "$$DISPLAY" ] && [ $$status -eq 1 ] || exit $$status; }

check: $(VENV)/.installed
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	$(PYTEST_ENV) $(PY) -m pytest -q -n auto -m "not slow and not window" $(PYTEST_ARGS)

test: $(VENV)/.installed
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	$(PYTEST_ENV) $(PY) -m pytest -n auto --dist loadgroup $(PYTEST_ARGS)

lint: $(VENV)/.installed
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

format: $(VENV)/.installed
	$(VENV)/bin/ruff format .
	$(VENV)/bin/ruff check --fix .

bench: $(VENV)/.ballpit
	$(VENV)/bin/ballpit bench

clean:
	rm -rf $(VENV) build dist src/*.egg-info
