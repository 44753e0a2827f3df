# Two commands matter (see README): `make up` and `make test`.
# Every target installs what it needs, so both work on a fresh clone.
SHELL := /bin/bash
PY := .venv/bin/python
PIP := .venv/bin/pip
STAMP := .venv/.installed
BPY_STAMP := .venv-bpy/.installed
FRONT_STAMP := frontend/node_modules/.installed
HOST ?= 127.0.0.1
PORT ?= 8000

.PHONY: up test install bpy frontend browser lint pytest vitest bench screenshots clean

up: install bpy frontend
	$(PY) scripts/up.py --host $(HOST) --port $(PORT)

test: install bpy frontend browser lint vitest pytest

install: $(STAMP)

$(STAMP): pyproject.toml setup.py motionlib/io/_parse.c motionlib/_kinematics.c motionlib/_dtw.c
	test -x $(PY) || python3 -m venv .venv
	$(PIP) install -q --upgrade pip
	$(PIP) install -q -e ".[dev,bench,plot]"
	touch $(STAMP)

# Blender as a module (FBX) in a virtualenv of its own: bpy pins numpy<2 (see the file).
bpy: $(BPY_STAMP)

$(BPY_STAMP): requirements-bpy.txt
	test -x .venv-bpy/bin/python || python3 -m venv .venv-bpy
	.venv-bpy/bin/pip install -q -r requirements-bpy.txt
	touch $(BPY_STAMP)

$(FRONT_STAMP): frontend/package.json frontend/package-lock.json
	cd frontend && npm ci --no-audit --no-fund
	touch $(FRONT_STAMP)

# The API types (frontend/src/api/schema.d.ts, checked in) are generated from the OpenAPI
# schema; under CI they are only checked against it, so a stale checked-in file fails.
frontend: $(FRONT_STAMP) install
	$(PY) manage.py spectacular --validate --fail-on-warn --file frontend/openapi.yml
	cd frontend && npm run $(if $(filter true,$(CI)),api-types:check,api-types)
	cd frontend && npm run build

# Browser tests drive Debian's Chromium; nothing downloads a browser of its own. Debian's
# ffmpeg gives the service ffprobe (it reads a reference video's codec, duration and frame
# rate) and the tests their real videos.
browser:
	@command -v chromium >/dev/null || { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium; }
	@command -v ffprobe >/dev/null || { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq ffmpeg; }

lint: install
	.venv/bin/ruff check .
	$(PY) manage.py makemigrations --check --dry-run

vitest: $(FRONT_STAMP)
	cd frontend && npm test

# The unit tests on the embedded default (SQLite), then the browser tests in a session of
# their own (its SQLite test database is a file, which the live server's threads need: the
# first test of a session decides the database for all), then the integration tests against PostgreSQL + Redis + real Celery workers, last so that the
# final line is that run's summary.
INTEGRATION_ENV := DATABASE_URL=postgres://postgres@127.0.0.1:5432/test \
	CELERY_BROKER_URL=redis://127.0.0.1:6379/15

# Both runs spread their tests over one process per core (pytest-xdist); an idle process
# takes tests from a busy one's queue, so one long test does not leave a core waiting at the
# end. Each process has its own test database (pytest-django suffixes it: _gw0, _gw1),
# temporary folders and var/ (tests/conftest.py); each integration test's Celery workers
# read that process's database from a Redis queue of their own.
PYTEST_WORKERS ?= auto
XDIST := -n $(PYTEST_WORKERS) --dist worksteal --durations=10

pytest: install
	$(PY) -m pytest -m "not integration and not e2e" $(XDIST)
	$(PY) -m pytest -m e2e tests/e2e $(XDIST)
	$(INTEGRATION_ENV) $(PY) -m pytest -m integration $(XDIST)

# Each benchmark's output goes to benchmarks/results/<name>.md (generated, committed: every
# figure quoted has one source, and a change shows as a diff), headed by date, commit and load.
# `python -m benchmarks` lists every benchmark; these are the ones cheap enough to rerun.
BENCHES := speed-io quality learning-curve speed-adapt points-read points-similar fbx-read \
	upload-to-candidates hour-take bulk-import capture-list-load poisoning annotation-import

bench: install bpy
	@command -v wrk >/dev/null || { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq wrk; } \
		|| echo "wrk not installed: the capture list benchmark uses its Python client"
	@for name in $(BENCHES); do $(PY) -m benchmarks $$name || exit 1; done

# The README's screenshots, taken by the browser tests.
screenshots: install frontend browser
	CUTROOM_SCREENSHOTS=1 $(PY) -m pytest tests/e2e -q -k "restores_the_review or gold_version or glb or fits_a_laptop or overview_and_a_working_window or plays_in_sync_with_the_take"

clean:
	rm -rf .venv .venv-bpy frontend/node_modules frontend/dist var
