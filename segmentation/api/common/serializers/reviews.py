"""JSON shapes of reviews (docs/api.md): a review, its cuts and segments, the edits
sent to it, label suggestions and the audit log."""

from drf_spectacular.utils import extend_schema_field
from rest_framework import serializers

from segmentation.api.common.serializers.base import Text, UserRefSerializer
from segmentation.api.common.serializers.captures import AdaptationSerializer
from segmentation.limits import text_limit
from segmentation.models import Cut, Label, Review, ReviewEvent
from segmentation.services.adaptation import adaptation_summary
from segmentation.services.attributes import review_values


class CutSerializer(serializers.Serializer):
    id = serializers.IntegerField(allow_null=True, help_text="null in a review not started yet")
    origin = serializers.ChoiceField(choices=Cut.ORIGINS)
    fate = serializers.ChoiceField(choices=Cut.FATES)
    candidate_frame = serializers.IntegerField(allow_null=True)
    frame = serializers.IntegerField()
    confidence = serializers.FloatField(allow_null=True)


class ReviewSegmentSerializer(serializers.Serializer):
    index = serializers.IntegerField()
    start = serializers.IntegerField()
    stop = serializers.IntegerField()
    label = serializers.CharField(allow_null=True)
    attributes = serializers.DictField(
        required=False, help_text="the segment's attribute values by attribute name (the project's schema: "
                  "GET /api/projects/{id}/attributes/)")


# A review's statuses, and that of the review a caller has not started yet (the schema's
# ReviewStateEnum, settings.SPECTACULAR_SETTINGS).
REVIEW_STATES = [*Review.STATUSES, ("not_started", "Not started")]


class ReviewSerializer(serializers.ModelSerializer):
    """A review as its edits answer it: its cuts and segments."""

    # null, and status not_started: the review the caller would start (GET …/review/).
    id = serializers.IntegerField(read_only=True, allow_null=True)
    status = serializers.ChoiceField(choices=REVIEW_STATES, read_only=True)
    annotator = serializers.SerializerMethodField()
    cuts = serializers.SerializerMethodField()
    segments = serializers.SerializerMethodField()

    class Meta:
        model = Review
        fields = [
            "id", "capture", "annotator", "run", "status", "version", "return_comment", "cuts", "segments",
        ]

    @extend_schema_field(UserRefSerializer)
    def get_annotator(self, review):
        return {"id": review.annotator_id, "username": review.annotator.username}

    @extend_schema_field(CutSerializer(many=True))
    def get_cuts(self, review):
        return self._cuts(review)

    def _cuts(self, review):
        """The review's cuts in frame order, read once for its cuts and its segments."""
        cached = getattr(self, "_cuts_of", None)
        if cached is not None and cached[0] is review:
            return cached[1]
        # Plain values, not a nested serializer per cut: a one-hour take has thousands.
        fields = list(CutSerializer().fields)
        cuts = [dict(zip(fields, row, strict=True))
                for row in review.cuts.order_by("frame", "id").values_list(*fields)]
        self._cuts_of = (review, cuts)
        return cuts

    @extend_schema_field(ReviewSegmentSerializer(many=True))
    def get_segments(self, review):
        # Label suggestions are not part of a review: they are computed by a worker and
        # read from …/review/suggestions/ (segmentation.similar.suggestions).
        kept = [(cut["id"], cut["frame"]) for cut in self._cuts(review) if cut["fate"] != "deleted"]
        values, starts = review_values(review), [None] + [cut_id for cut_id, _ in kept]
        return [{"index": index, "start": start, "stop": stop, "label": label,
                 "attributes": values.get(starts[index], {})}
                for index, start, stop, label in review.segments(kept=kept)]


class ReviewPageSerializer(ReviewSerializer):
    """A review as the review page opens it (GET): also where its candidates came from
    and the state of the project's learnt model."""

    adaptation = serializers.SerializerMethodField()

    class Meta(ReviewSerializer.Meta):
        fields = [*ReviewSerializer.Meta.fields, "adaptation"]

    @extend_schema_field(AdaptationSerializer)
    def get_adaptation(self, review):
        """Which project model the review's candidates came from (model_version null:
        the zero-shot detector), the project's newest model, its last failed training and,
        for a reviewer or admin, its last refused one. The page's review is its caller's own."""
        return adaptation_summary(review.run, review.capture.project_id, review.annotator)


class SuggestionSerializer(serializers.Serializer):
    start = serializers.IntegerField()
    stop = serializers.IntegerField()
    label = serializers.CharField(allow_null=True)
    probability = serializers.FloatField(
        allow_null=True, help_text="A proposal's mean probability over the span; null for a "
        "label the library suggests.")
    proposed = serializers.BooleanField(
        help_text="True: a frame model's proposed label (learnt from what the caller may "
        "see); false: the label the library's most similar segments suggest.")


class SuggestionsSerializer(serializers.Serializer):
    pending = serializers.BooleanField()
    suggestions = SuggestionSerializer(many=True)


class VersionSerializer(serializers.Serializer):
    version = serializers.IntegerField(min_value=1)


class RestoreSerializer(VersionSerializer):
    """Restore the review as it was right after its event ``event`` (an id of its log)."""

    event = serializers.IntegerField(min_value=1)


class InsertCutSerializer(VersionSerializer):
    frame = serializers.IntegerField()


class ChangeCutSerializer(VersionSerializer):
    fate = serializers.ChoiceField(choices=["accepted", "deleted", "pending"], required=False)
    frame = serializers.IntegerField(required=False)

    def validate(self, data):
        if ("fate" in data) == ("frame" in data):
            raise serializers.ValidationError("send either fate or frame (a move), not both")
        return data


class LabelSegmentSerializer(VersionSerializer):
    label = Text(text_limit(Label, "name"), allow_null=True)


class EventSerializer(serializers.ModelSerializer):
    user = serializers.SerializerMethodField()

    class Meta:
        model = ReviewEvent
        fields = ["id", "user", "action", "cut", "before", "after", "created_at"]

    def get_user(self, event) -> str | None:
        return event.user.username if event.user else None
