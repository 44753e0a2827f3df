"""Backup and restore of a whole installation: every row of the database (the projects, their
captures, reviews, gold versions, library segments and cut models), the stored files (the
originals and what was derived from them) and the similar-clip indexes.

A backup is one tar file holding ``manifest.json`` (its format, when it was made, the
migrations its rows belong to), ``db.json`` (the rows as Django serialises them, so a backup
made on the embedded SQLite default restores on PostgreSQL and the other way round),
``media/`` (``MEDIA_ROOT``) and ``similar/`` (``SIMILAR_INDEX_DIR``).

The rows are read in one transaction, so they are consistent with each other (on PostgreSQL
a repeatable-read snapshot; on SQLite writers wait while they are read). The files are copied
after: a file stored meanwhile is copied without a row pointing at it, which is harmless.

A backup restores into an empty installation only (no accounts, no projects, no stored
files), made by the same release: its rows fit that release's tables. An older backup is
restored with the release that made it, then upgraded with ``manage.py migrate``.
"""

import datetime
import io
import itertools
import json
import os
import tarfile
import tempfile
from pathlib import Path

from django.apps import apps
from django.conf import settings
from django.contrib.auth import get_user_model
from django.core import serializers
from django.core.management import call_command
from django.core.serializers.base import DeserializationError
from django.core.serializers.json import Serializer as JSONSerializer
from django.db import DEFAULT_DB_ALIAS, connection, connections, transaction
from django.db.migrations.loader import MigrationLoader
from django.db.migrations.recorder import MigrationRecorder
from django.utils import timezone

from segmentation.errors import CutroomError
from segmentation.models import Capture, Project

FORMAT = 1
# Rows every installation makes for itself as it migrates (content types and permissions,
# referred to by natural key), and what belongs to the running processes, not the work:
# sign-in sessions and the workers' heartbeats.
NOT_BACKED_UP = {"contenttypes", "auth.permission", "sessions", "segmentation.workerheartbeat"}


class BackupError(CutroomError):
    """A backup that cannot be made or restored here; the message says why."""


def do_backup(path):
    """Write a backup of this installation to ``path`` (replaced only once complete).

    Returns the manifest written.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="cutroom-backup-") as folder:
        rows = Path(folder) / "db.json"
        applied = _dump_rows(rows)
        manifest = {"format": FORMAT, "created": timezone.now().isoformat(),
                    "database": connection.vendor, "migrations": applied}
        partial = path.with_name(path.name + ".partial")
        with tarfile.open(partial, "w") as archive:
            _add_bytes(archive, "manifest.json", json.dumps(manifest, indent=1).encode())
            archive.add(rows, "db.json")
            for name, folder_path in _folders().items():
                if folder_path.is_dir():
                    archive.add(folder_path, name, filter=_files_only)
        os.replace(partial, path)
    return manifest


def _dump_rows(out):
    """Write every row to ``out`` in one transaction; the migrations applied, sorted."""
    outermost = not connection.in_atomic_block
    with transaction.atomic():
        if outermost and connection.vendor == "postgresql":
            with connection.cursor() as cursor:
                cursor.execute("SET TRANSACTION ISOLATION LEVEL REPEATABLE READ READ ONLY")
        applied = sorted([app, name] for app, name in
                         MigrationRecorder(connection).applied_migrations())
        with open(out, "w") as stream:
            _RowSerializer().serialize(_rows(), stream=stream, use_natural_foreign_keys=True)
    return applied


class _RowSerializer(JSONSerializer):
    """Django's JSON serialisation, with times to the microsecond (its encoder keeps
    milliseconds, which would change every time stamp and the order of rows made within
    the same millisecond)."""

    def _value_from_field(self, obj, field):
        value = field.value_from_object(obj)
        if isinstance(value, (datetime.datetime, datetime.time)):
            return value.isoformat()
        return super()._value_from_field(obj, field)


def _rows():
    """Every row to back up, models ordered so that natural keys resolve, rows by key."""
    by_app = {}
    for model in apps.get_models():
        meta = model._meta
        if (meta.proxy or not meta.managed or meta.app_label in NOT_BACKED_UP
                or meta.label_lower in NOT_BACKED_UP):
            continue
        by_app.setdefault(meta.app_config, []).append(model)
    ordered = serializers.sort_dependencies(by_app.items(), allow_cycles=True)
    return itertools.chain.from_iterable(
        model._base_manager.order_by("pk").iterator(chunk_size=500) for model in ordered)


def _files_only(member):
    """Files and folders; not what only a running process makes or uses (named pipes,
    sockets, device files), which no restore could put back, nor the similar indexes'
    empty ``.lock`` files, which a writer makes on this machine when it needs one."""
    if member.isreg() and member.name.endswith(".lock") and member.size == 0:
        return None
    return member if member.isreg() or member.isdir() else None


def _add_bytes(archive, name, data):
    info = tarfile.TarInfo(name)
    info.size, info.mtime = len(data), int(timezone.now().timestamp())
    archive.addfile(info, io.BytesIO(data))


def _folders():
    return {"media": Path(settings.MEDIA_ROOT), "similar": Path(settings.SIMILAR_INDEX_DIR)}


def do_restore(path):
    """Restore the backup at ``path`` into this (empty) installation: its tables are made,
    its rows loaded, its files put back. Returns the backup's manifest.

    BackupError if the file is not a backup, was made by another release, or this
    installation is not empty.
    """
    path = Path(path)
    with _open(path) as archive:
        manifest = _manifest(path, archive)
        _check_release(path, manifest)
        _check_empty_folders()
        call_command("migrate", interactive=False, verbosity=0)
        _check_empty_database()
        with tempfile.TemporaryDirectory(prefix="cutroom-restore-") as folder:
            rows = _member(path, archive, "db.json")
            target = Path(folder) / "db.json"
            with archive.extractfile(rows) as src, open(target, "wb") as dst:
                dst.write(src.read())
            try:
                with transaction.atomic():
                    call_command("loaddata", str(target), verbosity=0)
            except DeserializationError as exc:
                raise BackupError(f"{path}: db.json cannot be loaded ({exc})") from None
        for name, folder_path in _folders().items():
            members = [m for m in archive.getmembers() if m.name.startswith(f"{name}/")]
            for member in members:
                member.name = member.name[len(name) + 1:]
            folder_path.mkdir(parents=True, exist_ok=True)
            try:
                archive.extractall(folder_path, members=members, filter="data")
            except tarfile.FilterError as exc:
                raise BackupError(f"{path}: refused to restore {name}/{exc.tarinfo.name} "
                                  f"({exc})") from None
    return manifest


def _open(path):
    try:
        return tarfile.open(path, "r")
    except FileNotFoundError:
        raise BackupError(f"{path}: no such file") from None
    except (tarfile.TarError, OSError) as exc:
        raise BackupError(f"{path}: not a Cutroom backup (not a tar file: {exc})") from None


def _member(path, archive, name):
    try:
        return archive.getmember(name)
    except KeyError:
        raise BackupError(f"{path}: not a Cutroom backup (no {name} in it)") from None


def _manifest(path, archive):
    with archive.extractfile(_member(path, archive, "manifest.json")) as handle:
        try:
            manifest = json.load(handle)
        except ValueError as exc:
            raise BackupError(f"{path}: manifest.json is not JSON ({exc})") from None
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        found = manifest.get("format") if isinstance(manifest, dict) else None
        raise BackupError(f"{path}: backup format {found!r}; this release reads format {FORMAT}")
    return manifest


def _check_release(path, manifest):
    """The backup's rows fit this release's tables only if both have the same migrations."""
    loader = MigrationLoader(None, ignore_no_migrations=True)
    here = {tuple(key) for key in loader.disk_migrations}
    theirs = {tuple(key) for key in manifest.get("migrations", [])}
    if theirs != here:
        missing = sorted(f"{a}.{n}" for a, n in here - theirs)
        unknown = sorted(f"{a}.{n}" for a, n in theirs - here)
        raise BackupError(
            f"{path}: made by another release (migrations this release has and the backup "
            f"lacks: {', '.join(missing) or 'none'}; the backup has and this release lacks: "
            f"{', '.join(unknown) or 'none'}); restore it with the release that made it, then "
            "upgrade with `manage.py migrate`")


def _check_empty_database():
    users = get_user_model().objects.count()
    projects, captures = Project.objects.count(), Capture.objects.count()
    if users or projects or captures:
        name = connections[DEFAULT_DB_ALIAS].settings_dict["NAME"]
        raise BackupError(
            f"restore goes into an empty installation; the database {name} has {users} "
            f"account(s), {projects} project(s) and {captures} capture(s) (point DATABASE_URL "
            "at a new database)")


def _check_empty_folders():
    for setting, folder in (("MEDIA_ROOT", settings.MEDIA_ROOT),
                            ("SIMILAR_INDEX_DIR", settings.SIMILAR_INDEX_DIR)):
        folder = Path(folder)
        if folder.is_dir() and any(folder.iterdir()):
            raise BackupError(f"restore goes into an empty installation; {setting} {folder} is "
                              "not empty")
