"""Indexes for an annotator's list with a label filter on PostgreSQL.

Newest first, an annotator's list with a label filter is read as one run per label and
per visible run (their own segments, the gold ones; ``LibrarySegment.objects.runs_among``)
merged by id, as on SQLite (``0021``): as one OR it is every segment of the label in the
annotator's projects, filtered and sorted, for the page and again for its count. These
indexes give each run in id order with its filtered columns included, so the page and the
count read the matching rows alone. On PostgreSQL only; SQLite has its own (``0021``).
"""

from django.db import migrations

INCLUDED = ["duration", "agreement", "capture_id"]
INDEXES = {
    "libseg_pg_own_label": (["project_id", "superseded", "annotator_id", "label_id", "id"],
                            ["is_gold", *INCLUDED]),
    "libseg_pg_gold_label": (["project_id", "is_gold", "label_id", "id"],
                             ["superseded", "annotator_id", *INCLUDED]),
}


def create(apps, schema_editor):
    if schema_editor.connection.vendor != "postgresql":
        return
    for name, (keys, included) in INDEXES.items():
        schema_editor.execute(
            f'CREATE INDEX IF NOT EXISTS "{name}" ON "segmentation_librarysegment" '
            f'({", ".join(keys)}) INCLUDE ({", ".join(included)})')


def drop(apps, schema_editor):
    if schema_editor.connection.vendor != "postgresql":
        return
    for name in INDEXES:
        schema_editor.execute(f'DROP INDEX IF EXISTS "{name}"')


class Migration(migrations.Migration):
    dependencies = [("segmentation", "0021_library_list_sqlite_seek_indexes")]
    operations = [migrations.RunPython(create, drop, elidable=False)]
