"""Editing a project's label taxonomy: rename, recolour, hotkey, reorder, retire.

Segments refer to labels by row, so a rename shows everywhere at once; a retired label
stays on the segments that carry it but is no longer offered for new ones.
"""

from django.db import transaction

from segmentation.errors import Invalid
from segmentation.models import Label
from segmentation.services.projects import COLOR

HOTKEYS = "123456789"


def do_change_label(label, **fields):
    """Change any of name, color, hotkey (None clears it), retired; ValueError names the
    field and the clash."""
    project = label.project
    if "name" in fields:
        name = (fields["name"] or "").strip()
        if not name:
            raise Invalid("name: a label needs a name")
        if project.labels.filter(name=name).exclude(pk=label.pk).exists():
            raise Invalid(f"name: the project already has a label {name!r}")
        label.name = name
    if "color" in fields:
        if not COLOR.match(fields["color"] or ""):
            raise Invalid(f"color: must look like #rrggbb, got {fields['color']!r}")
        label.color = fields["color"].lower()
    if "hotkey" in fields:
        hotkey = fields["hotkey"] or None
        if hotkey is not None and (len(hotkey) != 1 or hotkey not in HOTKEYS):
            raise Invalid(f"hotkey: must be one of 1..9 or null, got {hotkey!r}")
        other = project.labels.filter(hotkey=hotkey).exclude(pk=label.pk).first() if hotkey else None
        if other:
            raise Invalid(f"hotkey: {hotkey!r} is already used by {other.name!r}")
        label.hotkey = hotkey
    if "retired" in fields:
        label.retired = bool(fields["retired"])
        if label.retired:
            label.hotkey = None  # frees the key for a label still in use
    label.save()
    return label


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
