"""Covering indexes for the library list on SQLite.

On PostgreSQL the list's indexes carry the filtered columns as ``INCLUDE`` columns, so a
page's ids and its capped count come from the index alone. SQLite has no ``INCLUDE``
(Django creates those indexes without it), and its rows hold the motion descriptor (about
5 KB) before the project, capture, annotator and label columns: a filter the index cannot
answer reads the row's overflow pages, for every row it looks at. These indexes are the
same ones with the included columns as trailing key columns, on SQLite only; each list
ordering has one whose leading columns give that order, so the page is read in order
from it and every filter is checked inside it.
"""

from django.db import migrations

FILTERED = ["project_id", "superseded", "label_id", "annotator_id", "is_gold", "duration",
            "agreement", "capture_id"]

# name -> leading key columns (in the list's order); the other filtered columns follow.
INDEXES = {
    "libseg_sqlite_all": ["superseded", "id"],
    "libseg_sqlite_recent": ["project_id", "superseded", "id"],
    "libseg_sqlite_label": ["project_id", "superseded", "label_id", "id"],
    "libseg_sqlite_annotator": ["project_id", "superseded", "annotator_id", "id"],
    "libseg_sqlite_agreement": ["project_id", "superseded", "agreement", "id"],
    "libseg_sqlite_duration": ["project_id", "superseded", "duration", "id"],
    "libseg_sqlite_capture": ["project_id", "superseded", "capture_id", "start", "id"],
    "libseg_sqlite_gold": ["project_id", "is_gold", "id"],
}


def columns(leading):
    return leading + [c for c in FILTERED if c not in leading]


def create_indexes(schema_editor, indexes):
    """``indexes`` (name -> leading columns) on SQLite; nothing elsewhere."""
    if schema_editor.connection.vendor != "sqlite":
        return
    for name, leading in indexes.items():
        quoted = ", ".join(f'"{c}"' for c in columns(leading))
        schema_editor.execute(
            f'CREATE INDEX IF NOT EXISTS "{name}" ON "segmentation_librarysegment" ({quoted})')


def drop_indexes(schema_editor, indexes):
    if schema_editor.connection.vendor != "sqlite":
        return
    for name in indexes:
        schema_editor.execute(f'DROP INDEX IF EXISTS "{name}"')


def create(apps, schema_editor):
    create_indexes(schema_editor, INDEXES)


def drop(apps, schema_editor):
    drop_indexes(schema_editor, INDEXES)


class Migration(migrations.Migration):
    dependencies = [("segmentation", "0019_cut_model_gate")]

    operations = [migrations.RunPython(create, drop, elidable=False)]
