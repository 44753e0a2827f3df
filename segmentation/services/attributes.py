"""Segment attributes: editing a project's schema, setting values on a review's segments,
carrying them into gold versions and the library.

A schema change never loses a stored value silently: an attribute that any segment of a
review or a gold version carries cannot be deleted, nor can a choice option that one
carries be removed, nor the kind of an attribute in use be changed. Each refusal says how
many segments carry it (the library's rows follow from those).
"""

from django.db import IntegrityError, transaction

from motionlib.errors import shorten
from segmentation.errors import Invalid
from segmentation.models import (
    GoldAttributeValue,
    LibraryAttributeValue,
    Project,
    SegmentAttribute,
    SegmentAttributeValue,
)
from segmentation.models.attributes import HOTKEYS, KINDS

NAME_LENGTH = 60


def _locked(project):
    """The project row, locked until the transaction ends, as ``services.projects`` locks
    it for taxonomy changes: schema changes run one after the other."""
    return Project.objects.select_for_update().get(pk=project.pk)


MAX_OPTIONS = 20


# ---- the schema ----------------------------------------------------------------------


def in_use(attribute, option=None):
    """How many review and gold segments carry ``attribute`` (with value ``option``)."""
    reviews = SegmentAttributeValue.objects.filter(attribute=attribute)
    gold = GoldAttributeValue.objects.filter(attribute=attribute)
    if option is not None:
        reviews, gold = reviews.filter(value=option), gold.filter(value=option)
    return reviews.count() + gold.count()


def _check_name(project, name, attribute=None):
    name = (name or "").strip() if isinstance(name, str) else name
    if not isinstance(name, str) or not name:
        raise Invalid("name: an attribute needs a name")
    if len(name) > NAME_LENGTH:
        raise Invalid(f"name: must be at most {NAME_LENGTH} characters, got {len(name)}")
    if ":" in name:
        raise Invalid(f"name: may not contain ':' (the library filters by name:value), got {name!r}")
    clash = project.attributes.filter(name=name)
    if attribute is not None:
        clash = clash.exclude(pk=attribute.pk)
    if clash.exists():
        raise Invalid(f"name: the project already has an attribute {name!r}")
    return name


def _check_options(kind, options):
    if kind != "choice":
        if options:
            raise Invalid(f"options: only a choice has options, not a {kind} attribute")
        return []
    if not isinstance(options, list) or not options:
        raise Invalid(f"options: a choice needs a list of options, got {shorten(repr(options))}")
    if len(options) > MAX_OPTIONS:
        raise Invalid(f"options: at most {MAX_OPTIONS} options, got {len(options)}")
    cleaned = []
    for i, option in enumerate(options):
        if not isinstance(option, str) or not option.strip() or len(option.strip()) > NAME_LENGTH:
            raise Invalid(f"options: option {i} must be text of 1 to {NAME_LENGTH} characters, "
                          f"got {shorten(repr(option))}")
        if option.strip() in cleaned:
            raise Invalid(f"options: {option.strip()!r} is listed twice")
        cleaned.append(option.strip())
    return cleaned


def _check_hotkey(project, hotkey, attribute=None):
    hotkey = hotkey or None
    if hotkey is None:
        return None
    if not isinstance(hotkey, str) or len(hotkey) != 1 or hotkey.lower() not in HOTKEYS:
        raise Invalid(f"hotkey: must be one of {', '.join(HOTKEYS)} (keys the review page "
                      f"leaves free) or null, got {shorten(repr(hotkey))}")
    hotkey = hotkey.lower()
    other = project.attributes.filter(hotkey=hotkey)
    if attribute is not None:
        other = other.exclude(pk=attribute.pk)
    if other.exists():
        raise Invalid(f"hotkey: {hotkey!r} is already used by {other.first().name!r}")
    return hotkey


def do_add_attribute(project, name, kind, options=None, hotkey=None):
    """A new attribute at the end of the project's schema; Invalid names the bad field."""
    if kind not in dict(KINDS):
        raise Invalid(f"kind: must be one of {', '.join(dict(KINDS))}, got {shorten(repr(kind))}")
    with transaction.atomic():
        project = _locked(project)
        attribute = SegmentAttribute(
            project=project, name=_check_name(project, name), kind=kind,
            options=_check_options(kind, options), hotkey=_check_hotkey(project, hotkey),
            position=project.attributes.count())
        try:
            with transaction.atomic():
                attribute.save()
        except IntegrityError:
            raise Invalid(f"name: the project already has an attribute {name!r} or that "
                          "hotkey") from None
    return attribute


def do_change_attribute(attribute, **fields):
    """Change its ``name``, ``options``, ``hotkey`` or ``kind``; an option that segments
    carry cannot be removed, nor the kind of an attribute in use changed."""
    with transaction.atomic():
        project = _locked(attribute.project)
        attribute.refresh_from_db()
        if "name" in fields:
            attribute.name = _check_name(project, fields["name"], attribute)
        kind = fields.get("kind", attribute.kind)
        if kind != attribute.kind:
            if kind not in dict(KINDS):
                raise Invalid(f"kind: must be one of {', '.join(dict(KINDS))}, got {shorten(repr(kind))}")
            used = in_use(attribute)
            if used:
                raise Invalid(f"kind: {attribute.name!r} is set on {used} segment(s); its kind "
                              "cannot change while they carry it")
            attribute.kind = kind
            attribute.options = []
        if "options" in fields or "kind" in fields:
            options = _check_options(kind, fields.get("options", attribute.options))
            for option in attribute.options:
                used = option not in options and in_use(attribute, option)
                if used:
                    raise Invalid(f"options: {option!r} of {attribute.name!r} is set on {used} "
                                  "segment(s); it cannot be removed while they carry it")
            attribute.options = options
        if "hotkey" in fields:
            attribute.hotkey = _check_hotkey(project, fields["hotkey"], attribute)
        attribute.save()
    return attribute


def do_delete_attribute(attribute):
    """Delete an attribute no segment carries; refused (naming how many) otherwise."""
    with transaction.atomic():
        used = in_use(attribute)
        if used:
            raise Invalid(f"attribute: {attribute.name!r} is set on {used} segment(s); it cannot "
                          "be deleted while they carry it (clear it on them first)")
        attribute.delete()


# ---- values on a review's segments ---------------------------------------------------


def review_values(review):
    """``{start cut id or None: {attribute name: shown value}}`` of a review."""
    found = {}
    rows = (SegmentAttributeValue.objects.filter(review=review).select_related("attribute")
            .order_by("attribute__position", "attribute_id"))
    for row in rows:
        found.setdefault(row.cut_id, {})[row.attribute.name] = row.attribute.shown(row.value)
    return found


def values_by_start(review):
    """``{segment start frame: {attribute id: stored text}}`` of a review's kept segments."""
    frames = dict(review.kept_frames())
    found = {}
    for cut_id, attribute_id, text in SegmentAttributeValue.objects.filter(review=review).values_list(
            "cut_id", "attribute_id", "value"):
        start = 0 if cut_id is None else frames.get(cut_id)
        if start is not None:
            found.setdefault(start, {})[attribute_id] = text
    return found


# ---- gold versions -------------------------------------------------------------------


def gold_by_start(capture):
    found = {}
    for start, attribute_id, text in GoldAttributeValue.objects.filter(capture=capture).values_list(
            "start", "attribute_id", "value"):
        found.setdefault(start, {})[attribute_id] = text
    return found


def check_gold_attributes(capture, n_segments, attributes):
    """``[{attribute id: text}]`` of a gold version's ``attributes`` (one ``{name: value}``
    per segment), validated; Invalid names the segment, attribute and value."""
    if not isinstance(attributes, list) or len(attributes) != n_segments:
        raise Invalid(f"attributes: expected {n_segments} entries (one per segment), got "
                      f"{len(attributes) if isinstance(attributes, list) else shorten(repr(attributes))}")
    schema = {a.name: a for a in capture.project.attributes.all()}
    result = []
    for i, values in enumerate(attributes):
        if not isinstance(values, dict):
            raise Invalid(f"attributes: segment {i} must be an object of name: value")
        stored = {}
        for name, value in values.items():
            if name not in schema:
                raise Invalid(f"attributes: segment {i} names {shorten(repr(name))}, which is not "
                              f"an attribute of this project ({', '.join(schema) or 'none defined'})")
            text = schema[name].parse(value, f"attributes: segment {i}")
            if text is not None:
                stored[schema[name].pk] = text
        result.append(stored)
    return result


def store_gold_values(capture, previous_spans, cuts, attributes=None, source_review=None):
    """Replace the gold version's attribute values (inside the gold workflow).

    ``attributes`` given: those. Else values travel with the segments they were set on:
    each gold segment keeps the values of the same span (start and stop) in the previous
    gold version (``previous_spans``: its ``(start, stop)``s); else takes those of the same
    span in ``source_review``, the review the reviewer copied; else, attribute by
    attribute, the value the capture's submitted reviews with that span agree on (a segment
    taken from one tier on the adjudication page; reviews that differ give none).
    """
    bounds = [0, *cuts, capture.n_frames]
    spans = list(zip(bounds[:-1], bounds[1:], strict=True))
    if attributes is not None:
        chosen = check_gold_attributes(capture, len(spans), attributes)
    else:
        previous, kept = gold_by_start(capture), set(previous_spans)
        source = _review_spans(source_review) if source_review is not None else {}
        agreed = _agreed_spans(capture)
        chosen = [previous.get(start, {}) if (start, stop) in kept
                  else source.get((start, stop)) or agreed.get((start, stop), {})
                  for start, stop in spans]
    GoldAttributeValue.objects.filter(capture=capture).delete()
    GoldAttributeValue.objects.bulk_create(
        GoldAttributeValue(capture=capture, start=start, attribute_id=attribute_id, value=text)
        for (start, _), values in zip(spans, chosen, strict=True)
        for attribute_id, text in values.items())


def _agreed_spans(capture):
    """``{(start, stop): {attribute id: text}}``: per span of the capture's submitted
    reviews, the values every review with that span that sets the attribute agrees on."""
    seen = {}
    for review in capture.reviews.filter(status="submitted"):
        for span, values in _review_spans(review).items():
            for attribute_id, text in values.items():
                seen.setdefault(span, {}).setdefault(attribute_id, set()).add(text)
    return {span: {a: next(iter(texts)) for a, texts in values.items() if len(texts) == 1}
            for span, values in seen.items()}


def _review_spans(review):
    values = values_by_start(review)
    return {(start, stop): values.get(start, {})
            for _, start, stop, _ in review.segments()}


# ---- the library ---------------------------------------------------------------------


def store_library_values(capture, rows):
    """Attribute rows of a capture's new library rows (saved, with ids): each takes the
    values of its segment in its review, or in the gold version."""
    by_review, gold = {}, None
    made = []
    for row in rows:
        if row.review_id is not None:
            if row.review_id not in by_review:
                by_review[row.review_id] = values_by_start(row.review)
            values = by_review[row.review_id].get(row.start, {})
        else:
            gold = gold_by_start(capture) if gold is None else gold
            values = gold.get(row.start, {})
        made += [LibraryAttributeValue(segment_id=row.pk, attribute_id=a, value=text)
                 for a, text in values.items()]
    LibraryAttributeValue.objects.bulk_create(made, batch_size=500)


def library_values(segment_ids):
    """``{segment id: [(attribute id, text)]}`` of library rows (to carry them to copies)."""
    found = {}
    for segment_id, attribute_id, text in LibraryAttributeValue.objects.filter(
            segment_id__in=segment_ids).values_list("segment_id", "attribute_id", "value"):
        found.setdefault(segment_id, []).append((attribute_id, text))
    return found


def copy_library_values(carried, new_ids):
    """Give the rows ``new_ids`` (old id -> new id) the values ``carried`` had."""
    LibraryAttributeValue.objects.bulk_create(
        [LibraryAttributeValue(segment_id=new_ids[old], attribute_id=a, value=text)
         for old, values in carried.items() if old in new_ids for a, text in values],
        batch_size=500)


def shown_library_values(segment_ids):
    """``{segment id: {attribute name: shown value}}`` for the API and the exports."""
    found = {pk: {} for pk in segment_ids}
    rows = (LibraryAttributeValue.objects.filter(segment_id__in=segment_ids)
            .select_related("attribute").order_by("attribute__position", "attribute_id"))
    for row in rows:
        found[row.segment_id][row.attribute.name] = row.attribute.shown(row.value)
    return found
