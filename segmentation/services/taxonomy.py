"""Editing a project's label taxonomy: rename, recolour, hotkey, reorder, retire, merge.

Segments refer to labels by row, so a rename shows everywhere at once; a retired label
stays on the segments that carry it but is no longer offered for new ones; a merged label
gives every segment, gold version, proposal and stored frame model that carries it to the
label it is merged into, and is deleted.

The project's stored frame models (``ProjectCutModel.labels_model``) know labels by id, so
a rename leaves them valid; a retired label's frames are read as unlabelled when a model
is used (``adaptation.proposals``); a merge relabels the stored models
(``motionlib.labelling.relabelled``): none needs a retraining.
"""

from django.db import IntegrityError, transaction

from motionlib.errors import shorten
from segmentation.errors import Invalid
from segmentation.limits import check_name, text_limit
from segmentation.models import (
    Adjudication,
    DetectionRun,
    Label,
    LabelSuggestion,
    LibrarySegment,
    ProjectCutModel,
    SegmentLabel,
)
from segmentation.services.projects import COLOR, _locked

HOTKEYS = "123456789"


def do_change_label(label, **fields):
    """Change any of name, color, hotkey (None clears it), retired; Invalid names the
    field and the clash.

    The project row is locked first, so concurrent changes of its labels run one after
    the other and the second sees the first's name and hotkey; where the database cannot
    lock (SQLite) the unique constraints still refuse the clash, said the same way.
    """
    with transaction.atomic():
        project = _locked(label.project)
        label.refresh_from_db()
        _apply(project, label, fields)
        try:
            with transaction.atomic():
                label.save()
        except IntegrityError:
            raise _clash(project, label) from None
    return label


def _apply(project, label, fields):
    if "name" in fields:
        name = (fields["name"] or "").strip()
        if not name:
            raise Invalid("name: a label needs a name")
        check_name("name", name, text_limit(Label, "name"))
        if project.labels.filter(name=name).exclude(pk=label.pk).exists():
            raise Invalid(f"name: the project already has a label {name!r}")
        label.name = name
    if "color" in fields:
        if not COLOR.match(fields["color"] or ""):
            raise Invalid(f"color: must look like #rrggbb, got {shorten(fields['color'])}")
        label.color = fields["color"].lower()
    if "hotkey" in fields:
        hotkey = fields["hotkey"] or None
        if hotkey is not None and (len(hotkey) != 1 or hotkey not in HOTKEYS):
            raise Invalid(f"hotkey: must be one of 1..9 or null, got {shorten(hotkey)}")
        other = project.labels.filter(hotkey=hotkey).exclude(pk=label.pk).first() if hotkey else None
        if other:
            raise Invalid(f"hotkey: {hotkey!r} is already used by {other.name!r}")
        label.hotkey = hotkey
    if "retired" in fields:
        label.retired = bool(fields["retired"])
        if label.retired:
            label.hotkey = None  # frees the key for a label still in use


def _clash(project, label):
    """The Invalid a unique constraint's refusal stands for: the name, else the hotkey."""
    if project.labels.filter(name=label.name).exclude(pk=label.pk).exists():
        return Invalid(f"name: the project already has a label {label.name!r}")
    return Invalid(f"hotkey: {label.hotkey!r} is already used by another label")


def do_reorder_labels(project, ids):
    """Put the taxonomy in the order of ``ids`` (every label of the project, once)."""
    labels = {label.pk: label for label in project.labels.all()}
    if not isinstance(ids, list) or sorted(ids) != sorted(labels):
        raise Invalid(f"order: must list each of the project's label ids once ({sorted(labels)}), "
                      f"got {ids!r}")
    with transaction.atomic():
        for position, pk in enumerate(ids):
            labels[pk].position = position
        Label.objects.bulk_update(labels.values(), ["position"])
    return [labels[pk] for pk in ids]


def do_merge_labels(source, target):
    """Merge the label ``source`` into ``target`` (both of one project): every review
    segment, gold version, library segment, suggestion, run proposal and stored frame
    model that carries ``source`` carries ``target`` instead, and ``source`` is deleted.
    Invalid when they are one label or of two projects. Returns ``target``."""
    if source.pk == target.pk:
        raise Invalid(f"into: a label cannot be merged into itself ({source.name!r})")
    if source.project_id != target.project_id:
        raise Invalid(f"into: label {target.pk} is not a label of {source.name!r}'s project")
    with transaction.atomic():
        project = _locked(source.project)
        SegmentLabel.objects.filter(label=source).update(label=target)
        LibrarySegment.objects.filter(label=source).update(label=target)
        LabelSuggestion.objects.filter(label=source).update(label=target)
        for gold in Adjudication.objects.filter(capture__project=project).select_for_update():
            if source.pk in gold.labels:
                gold.labels = [target.pk if x == source.pk else x for x in gold.labels]
                gold.save(update_fields=["labels"])
        for run in DetectionRun.objects.filter(capture__project=project, model_version__isnull=False):
            run.proposals = [{**p, "label": target.pk if p["label"] == source.pk else p["label"]}
                             for p in run.proposals]
            run.save(update_fields=["proposals"])
        _relabel_models(project, {str(source.pk): str(target.pk)})
        source.delete()
    target.refresh_from_db()
    return target


def _relabel_models(project, mapping):
    """The project's stored frame models with ``mapping`` applied (labels by id as text)."""
    from motionlib import labelling

    for row in ProjectCutModel.objects.filter(project=project).exclude(labels_model=""):
        try:
            model = labelling.FrameModel.from_json(row.labels_model)
        except ValueError:
            continue  # unreadable: it proposes nothing already (adaptation._parsed_labels)
        if set(mapping) & set(model.names):
            row.labels_model = labelling.relabelled(model, mapping).to_json()
            row.save(update_fields=["labels_model"])
