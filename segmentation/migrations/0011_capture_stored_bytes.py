"""Bytes each capture stores (original + ASF), for the per-project and per-user storage
quotas; existing captures are measured from their stored files."""

from django.db import migrations, models


def measure(apps, schema_editor):
    Capture = apps.get_model("segmentation", "Capture")
    for capture in Capture.objects.only("original", "asf").iterator():
        size = 0
        for field in (capture.original, capture.asf):
            try:
                size += field.size if field else 0
            except OSError:  # a missing file stores nothing
                pass
        Capture.objects.filter(pk=capture.pk).update(stored_bytes=size)


class Migration(migrations.Migration):
    dependencies = [("segmentation", "0010_label_suggestions")]

    operations = [
        migrations.AddField(
            model_name="capture",
            name="stored_bytes",
            field=models.PositiveBigIntegerField(default=0),
        ),
        migrations.RunPython(measure, migrations.RunPython.noop),
    ]
