"""Upgrading keeps the work: the previous release's database (``upgrade/v0.2.0.sqlite``, made
by ``upgrade/make_fixture.py`` from the tag v0.2.0) migrated by this release holds every
review's cuts and labels, the gold versions, the library segments and the cut models as that
release's people saw them (``upgrade/v0.2.0.holdings.json``)."""

import json
import shutil
import sqlite3
from pathlib import Path

from tests.segmentation.test_backup import fresh_installation, manage, run_installation

FIXTURES = Path(__file__).resolve().parent / "upgrade"
RELEASE = "v0.2.0"


def test_migrating_the_previous_release_keeps_every_review_gold_and_library_segment(tmp_path):
    database = tmp_path / "cutroom.sqlite3"
    shutil.copyfile(FIXTURES / f"{RELEASE}.sqlite", database)
    with sqlite3.connect(database) as conn:
        applied = {row[0] for row in conn.execute(
            "SELECT name FROM django_migrations WHERE app = 'segmentation'")}
    assert max(applied) == "0012_library_scale"  # the fixture is the previous release's
    env = fresh_installation(tmp_path, f"sqlite:///{database}")
    migrated = manage(env, "migrate", "--no-input")
    assert migrated.returncode == 0, migrated.stderr
    holdings = tmp_path / "holdings.json"
    run_installation(env, "holdings", holdings)
    expected = json.loads((FIXTURES / f"{RELEASE}.holdings.json").read_text())
    assert expected["library"] and expected["captures"]
    assert json.loads(holdings.read_text()) == expected
