"""JSON shapes of captures (docs/api.md): captures, uploads, detection runs, signals,
frames, and the project's cut model."""

from drf_spectacular.utils import extend_schema_field
from rest_framework import serializers

from segmentation.api.common.serializers.base import ErrorField, Text
from segmentation.limits import text_limit
from segmentation.models import Capture, DetectionRun, ProjectCutModel, Review


class CandidateSerializer(serializers.Serializer):
    frame = serializers.IntegerField()
    confidence = serializers.FloatField()


@extend_schema_field(CandidateSerializer(many=True))
class CandidatesField(serializers.JSONField):
    """A run's candidates as stored (a one-hour take has thousands: no serializer per item)."""


class ProposalSerializer(serializers.Serializer):
    """The label a project's frame model proposes for one segment between the candidates
    (``label``: a label id, null when it would most likely stay unlabelled)."""

    label = serializers.IntegerField(allow_null=True, read_only=True)
    probability = serializers.FloatField(read_only=True)


class RunSerializer(serializers.ModelSerializer):
    """A detection run. Its ``proposals`` were learnt from every annotator's reviews, so
    they are given only with ``context["sees_all_reviews"]`` (the project's reviewers and
    admins); anyone else gets [] (an annotator's own proposals: the review's suggestions)."""

    error = ErrorField()
    proposals = serializers.SerializerMethodField()
    params = serializers.DictField(read_only=True)
    timings = serializers.DictField(child=serializers.FloatField(), read_only=True)
    candidates = CandidatesField(read_only=True)

    class Meta:
        model = DetectionRun
        fields = [
            "id", "method", "params", "status", "error", "created_at", "finished_at",
            "timings", "candidates", "model_version", "model_n_takes", "proposals",
        ]

    @extend_schema_field(ProposalSerializer(many=True))
    def get_proposals(self, run):
        return run.proposals if self.context.get("sees_all_reviews") else []


class CutModelSerializer(serializers.ModelSerializer):
    """One training of a project's cut model: a version, why it failed, or why the model
    was refused (``refused``; no version)."""

    error = ErrorField()

    class Meta:
        model = ProjectCutModel
        fields = [
            "id", "version", "status", "error", "refused", "skipped", "n_takes", "n_cuts", "held_out_takes",
            "held_out_edits_per_cut", "held_out_f1", "held_out_basis", "seconds", "created_at", "finished_at",
        ]


class RunRequestSerializer(serializers.Serializer):
    method = Text(text_limit(DetectionRun, "method"), required=False, allow_blank=True, default="")
    params = serializers.DictField(required=False, default=dict)


class SkeletonSerializer(serializers.Serializer):
    joints = serializers.ListField(child=serializers.CharField())
    parents = serializers.ListField(child=serializers.IntegerField(), help_text="-1: the root")
    height = serializers.FloatField()
    up = serializers.CharField()
    kind = serializers.CharField(required=False, help_text="points: markers or tracked joints; "
                                 "parents are then the links drawn between them")
    marker_set = serializers.CharField(required=False, allow_null=True)


class CaptureSerializer(serializers.ModelSerializer):
    error = ErrorField()
    duration = serializers.FloatField(read_only=True)
    # A nested field, not RunSerializer(run) per row: that rebuilt the run's fields from
    # the model for every capture and was most of the capture list's time.
    latest_run = RunSerializer(read_only=True, allow_null=True)
    skeleton = serializers.SerializerMethodField()
    retryable = serializers.BooleanField(
        read_only=True, help_text="Failed, and not for a fault of the file: reading the stored "
        "original again may succeed (POST …/retry/).")

    class Meta:
        model = Capture
        fields = [
            "id", "project", "name", "format", "status", "error", "retryable", "fps", "n_frames",
            "duration", "n_joints", "checksum", "rest_pose_frame", "created_at",
            "latest_run", "skeleton", "animation", "source",
        ]

    @extend_schema_field(SkeletonSerializer(allow_null=True))
    def get_skeleton(self, capture):
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


class TeamReviewSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    annotator = serializers.CharField()
    status = serializers.ChoiceField(choices=Review.STATUSES)


class TeamSerializer(serializers.Serializer):
    """Who is assigned a capture, and each review's annotator and state."""

    assigned = serializers.ListField(child=serializers.CharField())
    reviews = TeamReviewSerializer(many=True)


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

    @extend_schema_field(TeamSerializer)
    def get_team(self, capture):
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


class UploadedSerializer(CaptureSerializer):
    duplicate = serializers.BooleanField(
        read_only=True, help_text="The project already had this file (same checksum): it is that capture.")

    class Meta(CaptureSerializer.Meta):
        fields = [*CaptureSerializer.Meta.fields, "duplicate"]


@extend_schema_field({"type": "array", "items": {"type": "number"}})
class FloatsField(serializers.JSONField):
    """A long list of numbers passed through as it is (no field call per value)."""


class SignalSerializer(serializers.Serializer):
    """A feature signal, sampled: value i is at frame start + i * step."""

    name = serializers.CharField()
    start = serializers.IntegerField()
    step = serializers.IntegerField()
    values = FloatsField(read_only=True)


class SignalsSerializer(serializers.Serializer):
    run = serializers.IntegerField(allow_null=True, help_text="The run they came from; null: none finished.")
    fps = serializers.FloatField(allow_null=True)
    n_frames = serializers.IntegerField(allow_null=True)
    signals = SignalSerializer(many=True)


class PackedSignalSerializer(serializers.Serializer):
    """A feature signal, sampled (``encoding=float32``): ``data`` is base64 of the values as
    little-endian float32; value i is at frame start + i * step."""

    name = serializers.CharField()
    start = serializers.IntegerField()
    step = serializers.IntegerField()
    dtype = serializers.ChoiceField(choices=["float32"])
    data = serializers.CharField()


class PackedSignalsSerializer(SignalsSerializer):
    signals = PackedSignalSerializer(many=True)


class FramesSerializer(serializers.Serializer):
    """Joint positions of frames start, start + step, … before stop (base64 of little-endian
    float32, shape (n_frames, n_joints, 3)); the client continues from stop."""

    start = serializers.IntegerField()
    stop = serializers.IntegerField()
    step = serializers.IntegerField()
    n_frames = serializers.IntegerField()
    n_joints = serializers.IntegerField()
    dtype = serializers.ChoiceField(choices=["float32"])
    data = serializers.CharField()


class HeldOutSerializer(serializers.Serializer):
    """A model's own figure: each reviewed take scored by a model fitted without it."""

    n_takes = serializers.IntegerField(help_text="Reviewed takes scored.")
    edits_per_cut = serializers.FloatField(help_text="Review edits per true cut there (manual cutting: 1).")
    f1 = serializers.FloatField(help_text="Boundary F1 there, within 1 s (meaningless when true_cuts is 0).")
    gold = serializers.IntegerField(allow_null=True, help_text="Of those, takes with a gold version "
                                    "(null: trained before this was kept).")
    shared = serializers.IntegerField(allow_null=True, help_text="Takes several annotators reviewed.")
    single = serializers.IntegerField(allow_null=True, help_text="Takes one annotator alone reviewed.")
    annotators = serializers.IntegerField(allow_null=True, help_text="Annotators behind the single takes.")
    true_cuts = serializers.IntegerField(allow_null=True, help_text="True cuts of the scored takes.")


class ProjectModelSerializer(serializers.Serializer):
    version = serializers.IntegerField()
    n_takes = serializers.IntegerField()
    n_cuts = serializers.IntegerField()
    held_out = HeldOutSerializer(allow_null=True, help_text="null: trained before the figure was kept.")


class AdaptationSerializer(serializers.Serializer):
    """Where a review's candidates came from, and the project's learnt model."""

    model_version = serializers.IntegerField(allow_null=True,
                                             help_text="The review's run; null: the zero-shot detector.")
    n_takes = serializers.IntegerField(allow_null=True, help_text="Reviewed takes that model learnt from.")
    held_out = HeldOutSerializer(allow_null=True, help_text="That model's own figure; null: zero-shot, "
                                 "or trained before the figure was kept.")
    project_model = ProjectModelSerializer(allow_null=True)
    training = serializers.BooleanField(help_text="A training is queued or running.")
    training_error = serializers.CharField(allow_null=True, help_text="Why the last training failed.")
    training_refused = serializers.CharField(
        allow_null=True, help_text="Why the model of the last training was refused (the project keeps its "
        "model; null for an annotator).")
    training_skipped = serializers.CharField(
        allow_null=True, help_text="Reviewed takes the last training left out and why, one a line (null for "
        "an annotator, or none left out).")
