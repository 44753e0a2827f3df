"""Editing a project's label taxonomy: rename, recolour, hotkey, reorder, retire.

Segments refer to labels by row, so a rename shows everywhere at once; a retired label
stays on the segments that carry it but is no longer offered for new ones.
"""

from django.db import IntegrityError, transaction

from motionlib.errors import shorten
from segmentation.errors import Invalid
from segmentation.limits import check_name, text_limit
from segmentation.models import Label
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
