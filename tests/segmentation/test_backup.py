"""``manage.py backup`` / ``restore`` on the embedded default (SQLite): a backup restored into an
empty installation (a new database, empty folders) gives byte-identical library exports, the
same stored files and the same similar-clip index; a restore refuses what it cannot do."""

import io
import json
import os
import re
import subprocess
import sys
import tarfile
import time
from pathlib import Path

import pytest
from django.conf import settings
from django.core.management import CommandError, call_command
from rest_framework.test import APIClient

from segmentation.models import LibrarySegment, ProjectCutModel
from tests.segmentation.installation import library_exports, populate

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def installation(db):
    project = populate()
    client = APIClient()
    client.force_authenticate(project.memberships.get(role="admin").user)
    return client


def fresh_installation(folder, database_url=None):
    """The environment of an empty installation under ``folder``."""
    env = {key: value for key, value in os.environ.items()
           if not key.startswith(("DATABASE_URL", "CUTROOM_", "CELERY_"))}
    env.update(
        PYTHONPATH=str(REPO), DJANGO_SETTINGS_MODULE="cutroom.settings",
        CUTROOM_VAR_DIR=str(folder), CUTROOM_MEDIA_ROOT=str(folder / "media"),
        CUTROOM_SIMILAR_INDEX_DIR=str(folder / "similar"),
        DATABASE_URL=database_url or f"sqlite:///{folder / 'cutroom.sqlite3'}")
    return env


def manage(env, *args):
    return subprocess.run([sys.executable, "manage.py", *args], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=600)


def run_installation(env, what, out):
    """``tests/segmentation/installation.py``'s ``main`` in the installation of ``env``."""
    done = subprocess.run([sys.executable, "-m", "tests.segmentation.installation", what,
                           str(out)], cwd=REPO, env=env, capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr


def exports_of(env, folder):
    """alice's downloads from the installation of ``env``, by file name."""
    folder.mkdir()
    run_installation(env, "exports", folder)
    return {path.name: path.read_bytes() for path in folder.iterdir()}


def tree(folder):
    # A similar index's empty lock file is made by whichever process writes it first.
    return {str(p.relative_to(folder)): p.read_bytes() for p in Path(folder).rglob("*")
            if p.is_file() and not (p.suffix == ".lock" and p.stat().st_size == 0)}


def test_a_restored_backup_exports_the_same_library_byte_for_byte(installation, tmp_path):
    before = library_exports(installation)
    assert LibrarySegment.objects.filter(is_gold=True).exists()
    assert ProjectCutModel.objects.filter(status="ready").exists()
    backup = tmp_path / "cutroom.tar"
    call_command("backup", str(backup), stdout=io.StringIO())
    restored = fresh_installation(tmp_path / "restored")
    done = manage(restored, "restore", str(backup))
    assert done.returncode == 0, done.stderr
    assert "restored" in done.stdout
    assert exports_of(restored, tmp_path / "after") == before
    assert tree(tmp_path / "restored" / "media") == tree(settings.MEDIA_ROOT)
    assert tree(tmp_path / "restored" / "similar") == tree(settings.SIMILAR_INDEX_DIR)


def test_it_leaves_out_what_only_a_running_process_uses(installation, tmp_path):
    os.mkfifo(Path(settings.MEDIA_ROOT) / "pipe")
    backup = tmp_path / "cutroom.tar"
    call_command("backup", str(backup), stdout=io.StringIO())
    with tarfile.open(backup) as archive:
        names = archive.getnames()
    assert "media/pipe" not in names and "db.json" in names
    restored = fresh_installation(tmp_path / "restored")
    done = manage(restored, "restore", str(backup))
    assert done.returncode == 0, done.stderr
    assert tree(tmp_path / "restored" / "media") == tree(settings.MEDIA_ROOT)


def test_the_same_library_exports_to_the_same_bytes(installation):
    first = library_exports(installation)["segments.zip"]
    time.sleep(2.1)  # zip entries are stamped to the 2 s: a later export, a later stamp
    assert library_exports(installation)["segments.zip"] == first


def test_it_restores_into_an_empty_installation_only(installation, tmp_path):
    backup = tmp_path / "cutroom.tar"
    call_command("backup", str(backup), stdout=io.StringIO())
    restored = fresh_installation(tmp_path / "restored")
    assert manage(restored, "restore", str(backup)).returncode == 0
    again = manage(restored, "restore", str(backup))
    assert again.returncode != 0
    assert "restore goes into an empty installation; MEDIA_ROOT" in again.stderr
    assert "Traceback" not in again.stderr


def test_it_refuses_a_database_that_is_not_empty(installation, tmp_path, settings):
    backup = tmp_path / "cutroom.tar"
    call_command("backup", str(backup), stdout=io.StringIO())
    settings.MEDIA_ROOT, settings.SIMILAR_INDEX_DIR = tmp_path / "empty", tmp_path / "none"
    with pytest.raises(CommandError, match=r"empty installation; the database .* has 3 "
                                           r"account\(s\), 1 project\(s\) and 2 capture"):
        call_command("restore", str(backup), stdout=io.StringIO())


def test_it_refuses_a_backup_of_another_release(tmp_path, db):
    backup = tmp_path / "old.tar"
    call_command("backup", str(backup), stdout=io.StringIO())
    with tarfile.open(backup) as archive:
        manifest = json.load(archive.extractfile("manifest.json"))
    manifest["migrations"] = [m for m in manifest["migrations"]
                              if m != ["segmentation", "0012_library_scale"]]
    rewritten = tmp_path / "older.tar"
    with tarfile.open(backup) as src, tarfile.open(rewritten, "w") as dst:
        for member in src.getmembers():
            data = src.extractfile(member).read() if member.isfile() else None
            if member.name == "manifest.json":
                data = json.dumps(manifest).encode()
                member.size = len(data)
            dst.addfile(member, io.BytesIO(data) if data is not None else None)
    done = manage(fresh_installation(tmp_path / "new"), "restore", str(rewritten))
    assert done.returncode != 0
    assert ("made by another release (migrations this release has and the backup lacks: "
            "segmentation.0012_library_scale; the backup has and this release lacks: none)"
            in done.stderr)
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize("content, problem", [
    (None, "no such file"),
    (b"not a tar file", "not a Cutroom backup (not a tar file"),
])
def test_it_names_a_file_that_is_not_a_backup(tmp_path, db, content, problem):
    path = tmp_path / "backup.tar"
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(CommandError, match=re.escape(f"backup.tar: {problem}")):
        call_command("restore", str(path), stdout=io.StringIO())


def test_it_names_a_backup_file_it_cannot_write(tmp_path, db):
    (tmp_path / "file").write_text("")
    with pytest.raises(CommandError, match="file/cutroom.tar: cannot write the backup"):
        call_command("backup", str(tmp_path / "file" / "cutroom.tar"), stdout=io.StringIO())


def test_it_names_rows_it_cannot_load(tmp_path, db, settings):
    backup = tmp_path / "cutroom.tar"
    call_command("backup", str(backup), stdout=io.StringIO())
    damaged = tmp_path / "damaged.tar"
    with tarfile.open(backup) as src, tarfile.open(damaged, "w") as dst:
        for member in src.getmembers():
            data = src.extractfile(member).read() if member.isfile() else None
            if member.name == "db.json":
                data = data[: len(data) // 2]
                member.size = len(data)
            dst.addfile(member, io.BytesIO(data) if data is not None else None)
    done = manage(fresh_installation(tmp_path / "new"), "restore", str(damaged))
    assert done.returncode != 0
    assert "damaged.tar: db.json cannot be loaded" in done.stderr
    assert "Traceback" not in done.stderr
