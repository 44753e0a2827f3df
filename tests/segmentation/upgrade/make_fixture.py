"""Make the upgrade fixture: a previous release's database with work in it, and that work as
its people saw it then.

    git tag v0.2.0 86adf0e          # once: the release before the upgrade (schema up to 0012)
    .venv/bin/python tests/segmentation/upgrade/make_fixture.py v0.2.0

Exports the tagged commit (``git archive``) into a temporary folder, builds its C extensions
there, and runs, with that release's code on a new SQLite database: its migrations, then
``tests/segmentation/installation.py``'s ``populate`` (takes ingested and detected, reviews,
gold, library segments, a cut model), then its ``holdings`` through that release's API. Writes
``<tag>.sqlite`` (the database; git ignores ``.sqlite3``) and ``<tag>.holdings.json`` beside this script; the stored
files are not kept (the upgrade test reads rows only). ``tests/segmentation/test_upgrade.py``
migrates a copy of the database with the current code and expects the same holdings.
"""

import importlib.util
import os
import shutil
import sqlite3
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
INSTALLATION = HERE.parent / "installation.py"


def main(tag):
    with tempfile.TemporaryDirectory(prefix="cutroom-fixture-") as folder:
        folder = Path(folder)
        source = folder / "source"
        source.mkdir()
        archive = subprocess.run(["git", "archive", tag], cwd=REPO, check=True,
                                 capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", str(source)], input=archive, check=True)
        subprocess.run([sys.executable, "setup.py", "-q", "build_ext", "--inplace"],
                       cwd=source, check=True, capture_output=True)
        database = folder / "cutroom.sqlite3"
        env = {key: value for key, value in os.environ.items()
               if not key.startswith(("DATABASE_URL", "CUTROOM_", "CELERY_"))}
        env.update(PYTHONPATH=str(source), DJANGO_SETTINGS_MODULE="cutroom.settings",
                   CUTROOM_VAR_DIR=str(folder / "var"), DATABASE_URL=f"sqlite:///{database}")
        subprocess.run([sys.executable, __file__, "--inside", str(HERE / f"{tag}.holdings.json")],
                       cwd=source, env=env, check=True)
        with sqlite3.connect(database) as conn:
            conn.execute("PRAGMA journal_mode=DELETE")
        with sqlite3.connect(database) as conn:
            conn.execute("VACUUM")
        shutil.copyfile(database, HERE / f"{tag}.sqlite")
    print(f"wrote {HERE / f'{tag}.sqlite'} and {HERE / f'{tag}.holdings.json'}")


def inside(holdings_path):
    """In the release's source folder, on its new database: migrate, populate, write the
    holdings."""
    import django

    django.setup()
    from django.core.management import call_command

    call_command("migrate", interactive=False, verbosity=0)
    spec = importlib.util.spec_from_file_location("installation", INSTALLATION)
    installation = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(installation)
    installation.populate()
    installation.main("holdings", holdings_path)


if __name__ == "__main__":
    if sys.argv[1] == "--inside":
        inside(sys.argv[2])
    else:
        main(sys.argv[1])
