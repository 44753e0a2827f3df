"""JSON shapes of docs/api.md. Output serializers mirror the records; input serializers
check the request's shape, and the services check its meaning."""

from drf_spectacular.utils import extend_schema_field
from rest_framework import serializers

from segmentation.limits import USERNAME_LENGTH, text_limit
from segmentation.models import (
    ROLES,
    Capture,
    Cut,
    DetectionRun,
    Label,
    Project,
    ProjectCutModel,
    Review,
    ReviewEvent,
)
from segmentation.services.adaptation import adaptation_summary


class Text(serializers.CharField):
    """A free-text request field with its bound (see ``segmentation.limits``): a longer
    value is refused saying the bound and its length, as the services do."""

    def __init__(self, max_length, **kwargs):
        messages = kwargs.pop("error_messages", {})
        messages.setdefault("max_length",
                            "must be at most {max_length} characters, got %(show_value)d")
        super().__init__(max_length=max_length, error_messages=messages, **kwargs)


class UserRefSerializer(serializers.Serializer):
    """A person as other records name them."""

    id = serializers.IntegerField()
    username = serializers.CharField()


class NamedRefSerializer(serializers.Serializer):
    """A capture or project as other records name them."""

    id = serializers.IntegerField()
    name = serializers.CharField()


class DetailSerializer(serializers.Serializer):
    """An answer that is only a sentence for the user."""

    detail = serializers.CharField()


class LabelSerializer(serializers.ModelSerializer):
    name = Text(text_limit(Label, "name"))
    hotkey = Text(text_limit(Label, "hotkey"), allow_null=True, required=False, default=None)
    color = Text(text_limit(Label, "color"), required=False, default="#888888")

    class Meta:
        model = Label
        fields = ["id", "name", "color", "hotkey", "position", "retired"]
        read_only_fields = ["position", "retired"]
        # Uniqueness is checked by the service with a message naming the clash.
        validators = []


class ProjectSerializer(serializers.Serializer):
    id = serializers.IntegerField(read_only=True)
    name = Text(text_limit(Project, "name"))
    role = serializers.SerializerMethodField()
    default_method = Text(text_limit(Project, "default_method"), required=False, allow_blank=True,
                          default="")
    default_params = serializers.DictField(required=False, default=dict)
    annotators_pick_unassigned = serializers.BooleanField(required=False, default=True)
    labels = LabelSerializer(many=True, read_only=True)

    # Never null: projects are listed to, and created by, their members only.
    @extend_schema_field(serializers.ChoiceField(choices=ROLES))
    def get_role(self, project):
        return project.role_of(self.context["request"].user)


class MyProjectSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    name = serializers.CharField()
    role = serializers.ChoiceField(choices=ROLES)


class LimitsSerializer(serializers.Serializer):
    """What the service admits, so the pages refuse the same."""

    max_joints = serializers.IntegerField()


class MeSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    username = serializers.CharField()
    projects = MyProjectSerializer(many=True)
    limits = LimitsSerializer()
    can_create_accounts = serializers.BooleanField()
    can_see_accounts = serializers.BooleanField(
        help_text="A site admin who may see accounts: inviting a name no account has is refused, "
        "saying so (to anyone else the answer is the same whether or not the name exists).")


class ParamSerializer(serializers.Serializer):
    """One parameter of a segmentation method."""

    type = serializers.CharField()
    default = serializers.JSONField(allow_null=True)
    min = serializers.FloatField(allow_null=True)
    max = serializers.FloatField(allow_null=True)
    description = serializers.CharField()


class MethodSerializer(serializers.Serializer):
    """A segmentation method of the catalogue and its parameters."""

    name = serializers.CharField()
    title = serializers.CharField()
    description = serializers.CharField()
    params = serializers.DictField(child=ParamSerializer())


class ErrorField(serializers.CharField):
    """A record's error text: null, not "", while it has none."""

    def __init__(self, **kwargs):
        super().__init__(read_only=True, allow_null=True, **kwargs)

    def to_representation(self, value):
        return value or None


class MemberSerializer(serializers.Serializer):
    id = serializers.IntegerField(source="user.id", read_only=True)
    username = Text(USERNAME_LENGTH, source="user.username", error_messages={
        "max_length": "must be 1 to {max_length} characters, got %(show_value)d"})
    role = serializers.ChoiceField(choices=ROLES)


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
    error = ErrorField()
    proposals = ProposalSerializer(many=True, read_only=True)
    params = serializers.DictField(read_only=True)
    timings = serializers.DictField(child=serializers.FloatField(), read_only=True)
    candidates = CandidatesField(read_only=True)

    class Meta:
        model = DetectionRun
        fields = [
            "id", "method", "params", "status", "error", "created_at", "finished_at",
            "timings", "candidates", "model_version", "model_n_takes", "proposals",
        ]


class CutModelSerializer(serializers.ModelSerializer):
    """One training of a project's cut model: a version, why it failed, or why the model
    was refused (``refused``; no version)."""

    error = ErrorField()

    class Meta:
        model = ProjectCutModel
        fields = [
            "id", "version", "status", "error", "refused", "n_takes", "n_cuts", "held_out_takes",
            "held_out_edits_per_cut", "held_out_f1", "seconds", "created_at", "finished_at",
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


class HeldOutSerializer(serializers.Serializer):
    """A model's own figure: each reviewed take scored by a model fitted without it."""

    n_takes = serializers.IntegerField(help_text="Reviewed takes scored.")
    edits_per_cut = serializers.FloatField(help_text="Review edits per true cut there (manual cutting: 1).")
    f1 = serializers.FloatField(help_text="Boundary F1 there, within 1 s.")


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
        # read from …/review/suggestions/ (segmentation.suggestions).
        kept = [(cut["id"], cut["frame"]) for cut in self._cuts(review) if cut["fate"] != "deleted"]
        return [{"index": index, "start": start, "stop": stop, "label": label}
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
