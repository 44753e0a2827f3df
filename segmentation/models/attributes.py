"""Segment attributes: a project's schema of what a segment may carry beside its label
(a choice such as quality good/usable/unusable, a free-text note, a yes/no such as "needs
cleanup"), and the values set on the segments of reviews, gold versions and the library.

Values are stored as text (``SegmentAttribute.parse`` makes it, ``shown`` reads it back):
one column that the library can filter on whatever the kind. A value belongs to the
attribute by identity, so a rename shows everywhere at once; an attribute or an option
that values carry cannot be taken away (``services.attributes``): nothing stored is lost.
"""

from django.db import models
from django.db.models import Q

from motionlib.errors import shorten
from segmentation.errors import Invalid
from segmentation.models.captures import Capture
from segmentation.models.library import LibrarySegment
from segmentation.models.projects import Project
from segmentation.models.reviews import Cut, Review

KINDS = (("choice", "Choice"), ("text", "Free text"), ("boolean", "Yes / no"))
# Keys the review page does not use already; an attribute's hotkey is one of them.
HOTKEYS = "befhjkopqtvwxy"
TRUE, FALSE = ("true", "yes", "1"), ("false", "no", "0")
MAX_TEXT = 500


class SegmentAttribute(models.Model):
    project = models.ForeignKey(Project, models.CASCADE, related_name="attributes")
    name = models.CharField(max_length=60)
    kind = models.CharField(max_length=10, choices=KINDS)
    # A choice's options in order ([] for the other kinds).
    options = models.JSONField(default=list, blank=True)
    hotkey = models.CharField(max_length=1, null=True, blank=True)  # noqa: DJ001
    position = models.PositiveIntegerField(default=0)

    class Meta:
        ordering = ["position", "id"]
        constraints = [
            models.UniqueConstraint(fields=["project", "name"], name="unique_attribute_name"),
            models.UniqueConstraint(fields=["project", "hotkey"], condition=Q(hotkey__isnull=False),
                                    name="unique_attribute_hotkey"),
        ]

    def __str__(self):
        return self.name

    def parse(self, value, where="value"):
        """The stored text of ``value`` (a JSON value as the API sends it), or Invalid
        naming the attribute, the value and what it may be. None clears."""
        if value is None:
            return None
        if self.kind == "boolean":
            text = str(value).strip().lower() if not isinstance(value, bool) else str(value).lower()
            if text in TRUE:
                return "true"
            if text in FALSE:
                return "false"
            raise Invalid(f"{where}: {self.name!r} is yes or no (true/false), got {shorten(value)}")
        if not isinstance(value, str):
            raise Invalid(f"{where}: {self.name!r} takes text, got {shorten(value)}")
        if self.kind == "choice":
            if value not in self.options:
                raise Invalid(f"{where}: {shorten(value)} is not an option of {self.name!r} "
                              f"({', '.join(self.options)})")
            return value
        value = value.strip()
        if len(value) > MAX_TEXT:
            raise Invalid(f"{where}: {self.name!r} must be at most {MAX_TEXT} characters, "
                          f"got {len(value)}")
        return value or None

    def shown(self, text):
        """The stored text as the API shows it: a boolean as true/false, else the text."""
        return text == "true" if self.kind == "boolean" else text


class SegmentAttributeValue(models.Model):
    """The value of one attribute on the segment of a review that starts at ``cut``
    (null: the first segment), keyed like ``SegmentLabel`` so that it follows the cut."""

    review = models.ForeignKey(Review, models.CASCADE, related_name="attribute_values")
    cut = models.ForeignKey(Cut, models.CASCADE, null=True, blank=True, related_name="+")
    attribute = models.ForeignKey(SegmentAttribute, models.RESTRICT, related_name="review_values")
    value = models.TextField(max_length=MAX_TEXT)

    class Meta:
        constraints = [
            models.UniqueConstraint(fields=["review", "cut", "attribute"], name="one_value_per_segment"),
            models.UniqueConstraint(fields=["review", "attribute"], condition=Q(cut__isnull=True),
                                    name="one_value_on_first_segment"),
        ]

    def __str__(self):
        return f"{self.attribute_id}={self.value} from {self.cut_id or 'the start'}"


class GoldAttributeValue(models.Model):
    """The value of one attribute on the gold segment of a capture that starts at ``start``
    (segments of a gold version are contiguous: a start names one). Replaced with the
    gold version."""

    capture = models.ForeignKey(Capture, models.CASCADE, related_name="gold_attribute_values")
    start = models.PositiveIntegerField()
    attribute = models.ForeignKey(SegmentAttribute, models.RESTRICT, related_name="gold_values")
    value = models.TextField(max_length=MAX_TEXT)

    class Meta:
        constraints = [models.UniqueConstraint(fields=["capture", "start", "attribute"],
                                               name="one_gold_value_per_segment")]

    def __str__(self):
        return f"{self.attribute_id}={self.value} at {self.start} of {self.capture_id}"


class LibraryAttributeValue(models.Model):
    """A library segment's attribute value, materialised with the segment (what the list
    filters on and the exports carry)."""

    segment = models.ForeignKey(LibrarySegment, models.CASCADE, related_name="attribute_values")
    attribute = models.ForeignKey(SegmentAttribute, models.CASCADE, related_name="+")
    value = models.TextField(max_length=MAX_TEXT)

    class Meta:
        indexes = [models.Index(fields=["attribute", "value", "segment"], name="libattr_value")]

    def __str__(self):
        return f"{self.attribute_id}={self.value} on {self.segment_id}"
