"""``manage.py backup`` / ``restore`` on PostgreSQL: a backup of a PostgreSQL installation
restored into a new PostgreSQL database (and into the embedded SQLite default) gives
byte-identical library exports and the same stored files."""

import io

import psycopg
import pytest
from django.conf import settings
from django.core.management import call_command
from django.db import connection
from rest_framework.test import APIClient

from segmentation.models import Project
from tests.segmentation.installation import library_exports, populate
from tests.segmentation.test_backup import exports_of, fresh_installation, manage, tree

pytestmark = pytest.mark.integration


@pytest.fixture
def empty_database(services_env):
    """A new, empty PostgreSQL database beside the test database; its URL."""
    db = connection.settings_dict
    server = f"postgres://{db['USER']}@{db['HOST'] or '127.0.0.1'}:{db['PORT'] or 5432}"
    name = f"{db['NAME']}_restored"

    def admin(statement):
        with psycopg.connect(f"{server}/postgres", autocommit=True) as conn:
            conn.execute(statement)

    admin(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')
    admin(f'CREATE DATABASE "{name}"')
    yield f"{server}/{name}"
    admin(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')


def test_a_postgresql_backup_restores_byte_for_byte(transactional_db, empty_database, tmp_path):
    project = populate()
    client = APIClient()
    client.force_authenticate(project.memberships.get(role="admin").user)
    before = library_exports(client)
    backup = tmp_path / "cutroom.tar"
    call_command("backup", str(backup), stdout=io.StringIO())
    for kind, url in (("postgresql", empty_database), ("sqlite", None)):
        folder = tmp_path / kind
        restored = fresh_installation(folder, url)
        done = manage(restored, "restore", str(backup))
        assert done.returncode == 0, done.stderr
        assert exports_of(restored, tmp_path / f"{kind}-exports") == before, kind
        assert tree(folder / "media") == tree(settings.MEDIA_ROOT), kind
        assert tree(folder / "similar") == tree(settings.SIMILAR_INDEX_DIR), kind
    # New rows in the restored database get new keys (its sequences moved past the rows').
    created = manage(fresh_installation(tmp_path / "postgresql", empty_database), "shell", "-c",
                     "from segmentation.models import Project; "
                     "print(Project.objects.create(name='After').pk)")
    assert created.returncode == 0, created.stderr
    assert int(created.stdout.split()[-1]) > Project.objects.order_by("pk").last().pk
