"""JSON shapes of docs/api.md. Output serializers mirror the records; input serializers
check the request's shape, and the services check its meaning."""

from rest_framework import serializers

from segmentation.models import ROLES, Capture, DetectionRun, Label, Review, ReviewEvent


class LabelSerializer(serializers.ModelSerializer):
    hotkey = serializers.CharField(allow_null=True, required=False, default=None)
    color = serializers.CharField(required=False, default="#888888")

    class Meta:
        model = Label
        fields = ["id", "name", "color", "hotkey"]
        # Uniqueness is checked by the service with a message naming the clash.
        validators = []


class ProjectSerializer(serializers.Serializer):
    id = serializers.IntegerField(read_only=True)
    name = serializers.CharField(max_length=200)
    role = serializers.SerializerMethodField()
    default_method = serializers.CharField(required=False, allow_blank=True, default="")
    default_params = serializers.DictField(required=False, default=dict)
    labels = LabelSerializer(many=True, read_only=True)

    def get_role(self, project) -> str | None:
        return project.role_of(self.context["request"].user)


class MemberSerializer(serializers.Serializer):
    id = serializers.IntegerField(source="user.id", read_only=True)
    username = serializers.CharField(source="user.username")
    role = serializers.ChoiceField(choices=[r for r, _ in ROLES])


class RunSerializer(serializers.ModelSerializer):
    error = serializers.SerializerMethodField()

    class Meta:
        model = DetectionRun
        fields = [
            "id", "method", "params", "status", "error", "created_at", "finished_at",
            "timings", "candidates",
        ]

    def get_error(self, run) -> str | None:
        return run.error or None


class RunRequestSerializer(serializers.Serializer):
    method = serializers.CharField(required=False, allow_blank=True, default="")
    params = serializers.DictField(required=False, default=dict)


class CaptureSerializer(serializers.ModelSerializer):
    error = serializers.SerializerMethodField()
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
            "latest_run", "skeleton",
        ]

    def get_error(self, capture) -> str | None:
        return capture.error or None

    def get_skeleton(self, capture) -> dict | None:
        return capture.skeleton if capture.status == "ready" else None


class RunSummarySerializer(serializers.ModelSerializer):
    """A run in a capture list row: its state and how many candidates, not the candidates."""

    error = serializers.SerializerMethodField()
    n_candidates = serializers.IntegerField(read_only=True)

    class Meta:
        model = DetectionRun
        fields = ["id", "method", "status", "error", "created_at", "finished_at", "n_candidates"]

    def get_error(self, run) -> str | None:
        return run.error or None


class CaptureListSerializer(CaptureSerializer):
    """A capture list row: a capture without its skeleton, its latest run summarised.
    Those two are most of a full capture's bytes and decoding time, and a list shows
    neither; ``GET /api/captures/{id}/`` has them."""

    latest_run = RunSummarySerializer(read_only=True, allow_null=True)

    class Meta(CaptureSerializer.Meta):
        fields = [f for f in CaptureSerializer.Meta.fields if f != "skeleton"]


class UploadSerializer(serializers.Serializer):
    file = serializers.FileField(allow_empty_file=True)
    asf = serializers.FileField(required=False, allow_empty_file=True)
    project = serializers.IntegerField()


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

    class Meta:
        model = Review
        fields = ["id", "capture", "annotator", "run", "status", "version", "cuts", "segments"]

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
