"""Drop the default detector's options that lost out of sample from stored parameters.

``tempo``, ``short_activity`` and ``short_uniformity`` are no longer parameters of the
``default`` method (they live on as a subclass scored by the quality benchmark), so
parameters that still hold them would be refused as unknown. They are dropped from every
project whose default method is ``default`` (or the registry's recommended one, "") and
from every ``default`` run that can still be detected (queued, processing or failed,
which a retry queues again); a finished run keeps the parameters it ran with, as its
record. Reversing leaves the parameters as they are: the options' shipped values were
their defaults, so a project without them detected the same.
"""

from django.db import migrations
from django.db.models import Q

LOSING = ("tempo", "short_activity", "short_uniformity")
BATCH = 500


def _holding(queryset, field):
    having = Q()
    for key in LOSING:
        having |= Q(**{f"{field}__has_key": key})
    return queryset.filter(having)


def _drop(queryset, field):
    changed = []
    for row in queryset.iterator(chunk_size=BATCH):
        params = getattr(row, field)
        setattr(row, field, {k: v for k, v in params.items() if k not in LOSING})
        changed.append(row)
        if len(changed) == BATCH:
            queryset.model.objects.bulk_update(changed, [field])
            changed = []
    if changed:
        queryset.model.objects.bulk_update(changed, [field])


def drop_losing_options(apps, schema_editor):
    Project = apps.get_model("segmentation", "Project")
    DetectionRun = apps.get_model("segmentation", "DetectionRun")
    projects = Project.objects.filter(default_method__in=("", "default"))
    _drop(_holding(projects, "default_params").only("pk", "default_params"), "default_params")
    runs = DetectionRun.objects.filter(method="default").exclude(status="ready")
    _drop(_holding(runs, "params").only("pk", "params"), "params")


class Migration(migrations.Migration):

    dependencies = [
        ("segmentation", "0012_library_scale"),
    ]

    operations = [
        migrations.RunPython(drop_losing_options, migrations.RunPython.noop),
    ]
