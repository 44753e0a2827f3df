"""Segments refer to labels by identity.

A library segment keeps only its label's id (its copy of the name is dropped), a gold
version stores label ids instead of names, a stored label suggestion points at its label
and an agreement summary keys its per-label figures by label id, so that renaming or
retiring a label leaves every stored segment, gold version and export consistent.

Existing rows are converted without losing any:

- a library segment keeps the label it points to; one that lost it (its label was gone)
  gets the project's label of its stored name;
- a gold segment takes the label of the gold library row of the same span (the label the
  name meant when the gold version was saved, even if it was renamed since), else the
  project's label of that name;
- a name no label of the project has any more becomes a retired label of that name, so
  the segment keeps it and nobody is offered it for new segments;
- suggestions and agreement summaries are derived data: a name no label has is dropped
  (the next request or submit recomputes it).
"""

from django.db import migrations, models
from django.db.models import OuterRef, Subquery

LIBRARY_INDEXES = ("libseg_label_duration", "libseg_list_recent", "libseg_list_all",
                   "libseg_list_label", "libseg_list_annotator", "libseg_list_agreement")


class ProjectLabels:
    """Label ids by project and name, creating a retired label for a name none has."""

    def __init__(self, Label):
        self.Label = Label
        self.known = {}

    def names(self, project_id):
        if project_id not in self.known:
            rows = self.Label.objects.filter(project_id=project_id).values_list("name", "id")
            self.known[project_id] = dict(rows)
        return self.known[project_id]

    def existing(self, project_id, name):
        return self.names(project_id).get(name)

    def id(self, project_id, name):
        names = self.names(project_id)
        if name not in names:
            position = self.Label.objects.filter(project_id=project_id).count()
            label = self.Label.objects.create(project_id=project_id, name=name, retired=True,
                                              position=position)
            names[name] = label.pk
        return names[name]


def to_label_ids(apps, schema_editor):
    labels = ProjectLabels(apps.get_model("segmentation", "Label"))
    _library_to_ids(apps, labels)
    _gold_to_ids(apps, labels)
    _suggestions_to_ids(apps, labels)
    _agreement_to_ids(apps, labels)
    if schema_editor.connection.vendor == "postgresql":
        # The deferred foreign-key checks of the updates run now, so that the same
        # transaction may alter the tables afterwards.
        schema_editor.execute("SET CONSTRAINTS ALL IMMEDIATE")


def _library_to_ids(apps, labels):
    LibrarySegment = apps.get_model("segmentation", "LibrarySegment")
    orphans = LibrarySegment.objects.filter(label__isnull=True)
    for project_id, name in set(orphans.values_list("project_id", "label_name")):
        orphans.filter(project_id=project_id, label_name=name).update(
            label_id=labels.id(project_id, name))


def _gold_to_ids(apps, labels):
    Adjudication = apps.get_model("segmentation", "Adjudication")
    LibrarySegment = apps.get_model("segmentation", "LibrarySegment")
    for gold in Adjudication.objects.select_related("capture").iterator():
        capture = gold.capture
        spans = dict(((start, stop), label_id) for start, stop, label_id in LibrarySegment.objects
                     .filter(capture_id=capture.pk, is_gold=True)
                     .values_list("start", "stop", "label_id"))
        bounds = [0, *gold.cuts, capture.n_frames]
        gold.labels = [
            None if name is None else spans.get((start, stop)) or labels.id(capture.project_id, name)
            for start, stop, name in zip(bounds[:-1], bounds[1:], gold.labels, strict=True)
        ]
        gold.save(update_fields=["labels"])


def _suggestions_to_ids(apps, labels):
    LabelSuggestion = apps.get_model("segmentation", "LabelSuggestion")
    named = LabelSuggestion.objects.exclude(label_name="")
    pairs = set(named.values_list("capture__project_id", "label_name"))
    for project_id, name in pairs:
        rows = named.filter(capture__project_id=project_id, label_name=name)
        label_id = labels.existing(project_id, name)
        if label_id is None:
            rows.delete()
        else:
            rows.update(label_id=label_id)


def _agreement_to_ids(apps, labels):
    CaptureAgreement = apps.get_model("segmentation", "CaptureAgreement")
    for row in CaptureAgreement.objects.select_related("capture").iterator():
        project_id = row.capture.project_id
        row.per_label = {str(labels.existing(project_id, name)): value
                         for name, value in row.per_label.items()
                         if labels.existing(project_id, name) is not None}
        row.save(update_fields=["per_label"])


def to_label_names(apps, schema_editor):
    Label = apps.get_model("segmentation", "Label")
    name_of = Subquery(Label.objects.filter(pk=OuterRef("label_id")).values("name")[:1])
    apps.get_model("segmentation", "LibrarySegment").objects.update(label_name=name_of)
    LabelSuggestion = apps.get_model("segmentation", "LabelSuggestion")
    LabelSuggestion.objects.filter(label__isnull=False).update(label_name=name_of)
    names = dict(Label.objects.values_list("id", "name"))
    for gold in apps.get_model("segmentation", "Adjudication").objects.iterator():
        gold.labels = [None if x is None else names[x] for x in gold.labels]
        gold.save(update_fields=["labels"])
    for row in apps.get_model("segmentation", "CaptureAgreement").objects.iterator():
        row.per_label = {names[int(key)]: value for key, value in row.per_label.items()}
        row.save(update_fields=["per_label"])
    if schema_editor.connection.vendor == "postgresql":
        schema_editor.execute("SET CONSTRAINTS ALL IMMEDIATE")


class Migration(migrations.Migration):

    dependencies = [
        ("segmentation", "0015_worker_heartbeat"),
    ]

    operations = [
        migrations.AddField(
            model_name="labelsuggestion",
            name="label",
            field=models.ForeignKey(blank=True, null=True, on_delete=models.deletion.CASCADE,
                                    related_name="+", to="segmentation.label"),
        ),
        migrations.RunPython(to_label_ids, to_label_names),
        *[migrations.RemoveIndex(model_name="librarysegment", name=name) for name in LIBRARY_INDEXES],
        # With a default, so that migrating back can add the columns again before filling them.
        migrations.AlterField(model_name="librarysegment", name="label_name",
                              field=models.CharField(default="", max_length=100)),
        migrations.AlterField(model_name="labelsuggestion", name="label_name",
                              field=models.CharField(blank=True, default="", max_length=100)),
        migrations.RemoveField(model_name="librarysegment", name="label_name"),
        migrations.RemoveField(model_name="labelsuggestion", name="label_name"),
        migrations.AlterField(
            model_name="librarysegment",
            name="label",
            field=models.ForeignKey(on_delete=models.deletion.RESTRICT, related_name="+",
                                    to="segmentation.label"),
        ),
        migrations.AddIndex(
            model_name="librarysegment",
            index=models.Index(fields=["project", "label", "duration"], name="libseg_label_duration"),
        ),
        # The bound of segmentation.limits (no change to the column).
        migrations.AlterField(model_name="review", name="return_comment",
                              field=models.TextField(blank=True, max_length=2000)),
        migrations.AddIndex(
            model_name="librarysegment",
            index=models.Index(fields=["project", "superseded", "-id"], include=("label", "duration", "agreement", "annotator", "is_gold", "capture"), name="libseg_list_recent"),
        ),
        migrations.AddIndex(
            model_name="librarysegment",
            index=models.Index(fields=["superseded", "-id"], include=("project", "label", "duration", "agreement", "annotator", "is_gold", "capture"), name="libseg_list_all"),
        ),
        migrations.AddIndex(
            model_name="librarysegment",
            index=models.Index(fields=["project", "superseded", "label", "id"], include=("duration", "agreement", "annotator", "is_gold", "capture"), name="libseg_list_label"),
        ),
        migrations.AddIndex(
            model_name="librarysegment",
            index=models.Index(fields=["project", "superseded", "annotator", "-id"], include=("label", "duration", "agreement", "is_gold", "capture"), name="libseg_list_annotator"),
        ),
        migrations.AddIndex(
            model_name="librarysegment",
            index=models.Index(fields=["project", "superseded", "-agreement", "-id"], include=("label", "duration", "annotator", "is_gold", "capture"), name="libseg_list_agreement"),
        ),
    ]
