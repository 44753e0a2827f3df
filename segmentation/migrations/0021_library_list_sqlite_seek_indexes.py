"""More covering indexes for the library list on SQLite (as in 0020: the
filtered columns trail the leading ones).

- A label's segments by duration, so that a label filter with a duration range counts
  its matches by seeking to the range (through the label's index it reads every segment
  of the label, through the duration one every segment of the range).
"""

from importlib import import_module

from django.db import migrations

covering = import_module("segmentation.migrations.0020_library_list_sqlite_indexes")

INDEXES = {
    "libseg_sqlite_label_duration": ["project_id", "superseded", "label_id", "duration", "id"],
}


def create(apps, schema_editor):
    covering.create_indexes(schema_editor, INDEXES)


def drop(apps, schema_editor):
    covering.drop_indexes(schema_editor, INDEXES)


class Migration(migrations.Migration):
    dependencies = [("segmentation", "0020_library_list_sqlite_indexes")]

    operations = [migrations.RunPython(create, drop, elidable=False)]
