"""More covering indexes for the library list on SQLite (as in 0020: the
filtered columns trail the leading ones).

- A label's segments by duration, so that a label filter with a duration range counts
  its matches by seeking to the range (through the label's index it reads every segment
  of the label, through the duration one every segment of the range).
- An annotator's segments and the gold ones, each newest first, across projects and for
  one label of a project, which an annotator's list reads as two runs merged by id
  (``LibrarySegment.objects.visible_runs``): ``annotator = me OR gold`` can be read in id
  order from no index.
"""

from importlib import import_module

from django.db import migrations

covering = import_module("segmentation.migrations.0020_library_list_sqlite_indexes")

INDEXES = {
    "libseg_sqlite_label_duration": ["project_id", "superseded", "label_id", "duration", "id"],
    "libseg_sqlite_own": ["superseded", "annotator_id", "id"],
    "libseg_sqlite_all_gold": ["is_gold", "id"],
    # The same two runs for one label (a label filter, one part per label's project).
    "libseg_sqlite_own_label": ["project_id", "superseded", "annotator_id", "label_id", "id"],
    "libseg_sqlite_gold_label": ["project_id", "is_gold", "label_id", "id"],
}


def create(apps, schema_editor):
    covering.create_indexes(schema_editor, INDEXES)


def drop(apps, schema_editor):
    covering.drop_indexes(schema_editor, INDEXES)


class Migration(migrations.Migration):
    dependencies = [("segmentation", "0020_library_list_sqlite_indexes")]

    operations = [migrations.RunPython(create, drop, elidable=False)]
