"""JSON shapes of docs/api.md. Output serializers mirror the records; input serializers
check the request's shape, and the services check its meaning."""

from rest_framework import serializers

from segmentation.models import (
    ROLES,
    Capture,
    DetectionRun,
    Label,
    ProjectCutModel,
    Review,
    ReviewEvent,
)


class LabelSerializer(serializers.ModelSerializer):
    hotkey = serializers.CharField(allow_null=True, required=False, default=None)
    color = serializers.CharField(required=False, default="#888888")

    class Meta:
        model = Label
        fields = ["id", "name", "color", "hotkey", "position", "retired"]
        read_only_fields = ["position", "retired"]
        # Uniqueness is checked by the service with a message naming the clash.
        validators = []


class ProjectSerializer(serializers.Serializer):
    id = serializers.IntegerField(read_only=True)
    name = serializers.CharField(max_length=200)
    role = serializers.SerializerMethodField()
    default_method = serializers.CharField(required=False, allow_blank=True, default="")
    default_params = serializers.DictField(required=False, default=dict)
    annotators_pick_unassigned = serializers.BooleanField(required=False, default=True)
    labels = LabelSerializer(many=True, read_only=True)

    def get_role(self, project) -> str | None:
        return project.role_of(self.context["request"].user)


class ErrorField(serializers.CharField):
    """A record's error text: null, not "", while it has none."""

    def __init__(self, **kwargs):
        super().__init__(read_only=True, allow_null=True, **kwargs)

    def to_representation(self, value):
        return value or None


class MemberSerializer(serializers.Serializer):
    id = serializers.IntegerField(source="user.id", read_only=True)
    username = serializers.CharField(source="user.username")
    role = serializers.ChoiceField(choices=[r for r, _ in ROLES])


class RunSerializer(serializers.ModelSerializer):
    error = ErrorField()

    class Meta:
        model = DetectionRun
        fields = [
            "id", "method", "params", "status", "error", "created_at", "finished_at",
            "timings", "candidates", "model_version", "model_n_takes",
        ]


class CutModelSerializer(serializers.ModelSerializer):
    """One training of a project's cut model: a version, or why it failed."""

    error = serializers.SerializerMethodField()

    class Meta:
        model = ProjectCutModel
        fields = [
            "id", "version", "status", "error", "n_takes", "n_cuts", "seconds", "created_at",
            "finished_at",
        ]

    def get_error(self, job) -> str | None:
        return job.error or None


class RunRequestSerializer(serializers.Serializer):
    method = serializers.CharField(required=False, allow_blank=True, default="")
    params = serializers.DictField(required=False, default=dict)


class CaptureSerializer(serializers.ModelSerializer):
    error = ErrorField()
    duration = serializers.FloatField(read_only=True)
    # A nested field, not RunSerializer(run) per row: that rebuilt the run's fields from
    # the model for every capture and was most of the capture list's time.
    latest_run = RunSerializer(read_only=True, allow_null=True)
    skeleton = serializers.SerializerMethodField()

    class Meta:
        model = Capture
        fields = [
            "id", "project", "name", "format", "status", "error", "fps", "n_frames",
            "duration", "n_joints", "checksum", "rest_pose_frame", "created_at",
            "latest_run", "skeleton", "animation", "source",
        ]

    def get_skeleton(self, capture) -> dict | None:
        return capture.skeleton if capture.status == "ready" else None


class RunSummarySerializer(serializers.ModelSerializer):
    """A run in a capture list row: its state and how many candidates, not the candidates."""

    error = ErrorField()
    n_candidates = serializers.IntegerField(read_only=True)

    class Meta:
        model = DetectionRun
        fields = [
            "id", "method", "status", "error", "created_at", "finished_at", "n_candidates",
            "model_version", "model_n_takes",
        ]


class CaptureListSerializer(CaptureSerializer):
    """A capture list row: a capture without its skeleton, its latest run summarised.
    Those two are most of a full capture's bytes and decoding time, and a list shows
    neither; ``GET /api/captures/{id}/`` has them."""

    latest_run = RunSummarySerializer(read_only=True, allow_null=True)
    # Someone opened it for review: its candidates can no longer be re-detected.
    review_started = serializers.BooleanField(read_only=True, default=False)
    team = serializers.SerializerMethodField()

    class Meta(CaptureSerializer.Meta):
        fields = [f for f in CaptureSerializer.Meta.fields if f != "skeleton"] + ["review_started", "team"]

    def get_team(self, capture) -> dict:
        """Who is assigned, and each review's annotator and state (from the prefetch)."""
        return {
            "assigned": [a.annotator.username for a in capture.assignments.all()],
            "reviews": [{"id": r.pk, "annotator": r.annotator.username, "status": r.status}
                        for r in sorted(capture.reviews.all(), key=lambda r: r.pk)],
        }


class UploadSerializer(serializers.Serializer):
    file = serializers.FileField(allow_empty_file=True)
    asf = serializers.FileField(required=False, allow_empty_file=True)
    project = serializers.IntegerField(min_value=1, max_value=2**63 - 1)


class CutSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    origin = serializers.CharField()
    fate = serializers.CharField()
    candidate_frame = serializers.IntegerField(allow_null=True)
    frame = serializers.IntegerField()
    confidence = serializers.FloatField(allow_null=True)


class ReviewSerializer(serializers.ModelSerializer):
    annotator = serializers.SerializerMethodField()
    cuts = serializers.SerializerMethodField()
    segments = serializers.SerializerMethodField()
    adaptation = serializers.SerializerMethodField()

    class Meta:
        model = Review
        fields = [
            "id", "capture", "annotator", "run", "status", "version", "return_comment", "cuts", "segments",
            "adaptation",
        ]

    def get_adaptation(self, review) -> dict:
        """Which project model the review's candidates came from (model_version null:
        the zero-shot detector), the project's newest model and its last failed training."""
        from segmentation.services.adaptation import adaptation_summary

        return adaptation_summary(review.run, review.capture.project_id)

    def get_annotator(self, review) -> dict:
        return {"id": review.annotator_id, "username": review.annotator.username}

    def get_cuts(self, review) -> list[dict]:
        # Plain values, not a nested serializer per cut: a one-hour take has thousands.
        fields = list(CutSerializer().fields)
        return [dict(zip(fields, row, strict=True))
                for row in review.cuts.order_by("frame", "id").values_list(*fields)]

    def get_segments(self, review) -> list[dict]:
        # Label suggestions are not part of a review: they are computed by a worker and
        # read from …/review/suggestions/ (segmentation.suggestions).
        return [{"index": index, "start": start, "stop": stop, "label": label}
                for index, start, stop, label in review.segments()]


class SuggestionSerializer(serializers.Serializer):
    start = serializers.IntegerField()
    stop = serializers.IntegerField()
    label = serializers.CharField(allow_null=True)


class SuggestionsSerializer(serializers.Serializer):
    pending = serializers.BooleanField()
    suggestions = SuggestionSerializer(many=True)


class VersionSerializer(serializers.Serializer):
    version = serializers.IntegerField(min_value=1)


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
    label = serializers.CharField(allow_null=True)


class EventSerializer(serializers.ModelSerializer):
    user = serializers.SerializerMethodField()

    class Meta:
        model = ReviewEvent
        fields = ["id", "user", "action", "cut", "before", "after", "created_at"]

    def get_user(self, event) -> str | None:
        return event.user.username if event.user else None
