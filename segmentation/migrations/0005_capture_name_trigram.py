"""A trigram index for the capture list's ``?search=`` (a case-insensitive substring).

``name__icontains`` is ``UPPER(name::text) LIKE UPPER('%…%')`` on PostgreSQL, which no
b-tree index serves: without this index every search scans the table. pg_trgm is a
trusted extension (PostgreSQL 13+), so the database owner can create it. SQLite (the
embedded default) gets nothing: a scan is fine at the sizes it serves.
"""

from django.db import migrations

INDEX = "capture_name_trgm"


def create(apps, schema_editor):
    if schema_editor.connection.vendor != "postgresql":
        return
    schema_editor.execute("CREATE EXTENSION IF NOT EXISTS pg_trgm")
    schema_editor.execute(
        f"CREATE INDEX IF NOT EXISTS {INDEX} ON segmentation_capture "
        "USING gin (UPPER(name::text) gin_trgm_ops)"
    )


def drop(apps, schema_editor):
    if schema_editor.connection.vendor == "postgresql":
        schema_editor.execute(f"DROP INDEX IF EXISTS {INDEX}")


class Migration(migrations.Migration):

    dependencies = [("segmentation", "0004_capture_newest_first")]

    operations = [migrations.RunPython(create, drop)]
