"""Setting a segment attribute on a review: a review edit like labelling a segment, kept
apart from the schema (``services.attributes``), which the library and gold workflows use."""

from django.db import transaction

from segmentation.errors import Invalid
from segmentation.models import SegmentAttributeValue
from segmentation.services.reviews import _log, _write


def find_attribute(project, name):
    attribute = project.attributes.filter(name=name).first()
    if attribute is None:
        names = ", ".join(project.attributes.values_list("name", flat=True)) or "none defined"
        raise Invalid(f"attribute: {str(name)[:100]!r} is not an attribute of this project ({names})")
    return attribute


def do_set_attribute(review, user, index, name, value, version):
    """Set (or clear, with None) attribute ``name`` of segment ``index``: a review edit
    (it moves the version and is logged), validated against the project's schema."""
    with transaction.atomic():
        _write(review, version)
        try:
            start_cut = review.segment_start_cut(index)
        except IndexError:
            raise Invalid(f"index: the review has no segment {index}") from None
        attribute = find_attribute(review.capture.project, name)
        text = attribute.parse(value, "value")
        row = SegmentAttributeValue.objects.filter(review=review, cut=start_cut, attribute=attribute).first()
        before = attribute.shown(row.value) if row else None
        if text is None:
            if row:
                row.delete()
        elif row:
            row.value = text
            row.save(update_fields=["value"])
        else:
            SegmentAttributeValue.objects.create(review=review, cut=start_cut, attribute=attribute, value=text)
        _log(review, user, "attribute", start_cut,
             before={"index": index, "attribute": attribute.name, "value": before},
             after={"index": index, "attribute": attribute.name, "value": attribute.shown(text) if text else None})
    return review
