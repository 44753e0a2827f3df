"""``GET/PUT /api/captures/{id}/adjudication/``: every review of a capture side by side,
and the gold version a reviewer or admin makes of them."""

from django.urls import path
from drf_spectacular.utils import extend_schema
from rest_framework import serializers
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation.api.common.params import body
from segmentation.api.common.serializers.agreement import AgreementSerializer
from segmentation.api.common.serializers.base import (
    NamedRefSerializer,
    Text,
    UserRefSerializer,
)
from segmentation.api.common.serializers.gold import (
    GoldBodySerializer,
    SpanSerializer,
    StaleGoldSerializer,
    gold_body,
)
from segmentation.errors import Invalid
from segmentation.limits import text_limit
from segmentation.models import Adjudication, Label, Review
from segmentation.queries.access import staff_capture
from segmentation.services import agreement
from segmentation.services.gold import do_save_gold


class AdjudicationCaptureSerializer(NamedRefSerializer):
    fps = serializers.FloatField(allow_null=True)
    n_frames = serializers.IntegerField(allow_null=True)
    project = serializers.IntegerField()


class AdjudicationLabelSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    name = serializers.CharField()
    color = serializers.CharField()
    hotkey = serializers.CharField(allow_null=True)
    retired = serializers.BooleanField(help_text="Kept on segments that carry it; not offered "
                                                 "for new ones")


class AdjudicationReviewSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    annotator = UserRefSerializer()
    status = serializers.ChoiceField(choices=Review.STATUSES)
    cuts = serializers.ListField(child=serializers.IntegerField())
    segments = SpanSerializer(many=True)


class AdjudicationSerializer(serializers.Serializer):
    capture = AdjudicationCaptureSerializer()
    labels = AdjudicationLabelSerializer(many=True)
    reviews = AdjudicationReviewSerializer(many=True)
    gold = GoldBodySerializer(allow_null=True)
    agreement = AgreementSerializer()


class GoldSerializer(serializers.Serializer):
    cuts = serializers.ListField(child=serializers.IntegerField())
    labels = serializers.ListField(child=Text(text_limit(Label, "name"), allow_null=True))
    version = serializers.IntegerField(min_value=0)
    source_review = serializers.IntegerField(required=False, allow_null=True)
    attributes = serializers.ListField(
        child=serializers.DictField(), required=False, allow_null=True,
        help_text="one {attribute name: value} per segment; when omitted, unchanged segments "
                  "keep theirs and segments copied from source_review bring theirs")


def adjudication_body(capture):
    reviews = Review.objects.filter(capture=capture).select_related("annotator", "capture")
    reviews = reviews.prefetch_related("cuts", "segment_labels__label").order_by("id")
    gold = Adjudication.objects.select_related("adjudicator").filter(capture=capture).first()
    return {
        "capture": {"id": capture.pk, "name": capture.name, "fps": capture.fps,
                    "n_frames": capture.n_frames, "project": capture.project_id},
        "labels": [{"id": x.pk, "name": x.name, "color": x.color, "hotkey": x.hotkey,
                    "retired": x.retired} for x in capture.project.labels.all()],
        "reviews": [
            {"id": r.pk, "annotator": {"id": r.annotator_id, "username": r.annotator.username},
             "status": r.status, "cuts": agreement.review_cuts(r),
             "segments": [{"start": a, "stop": b, "label": c}
                          for a, b, c in agreement.review_segments(r)]}
            for r in reviews
        ],
        "gold": gold_body(gold),
        "agreement": agreement.capture_agreement(capture),
    }


class AdjudicationView(APIView):
    @extend_schema(responses=AdjudicationSerializer)
    def get(self, request, pk):
        return Response(AdjudicationSerializer(adjudication_body(staff_capture(request.user, pk))).data)

    @extend_schema(request=GoldSerializer, responses={200: AdjudicationSerializer, 409: StaleGoldSerializer})
    def put(self, request, pk):
        capture = staff_capture(request.user, pk)
        data = body(request, GoldSerializer)
        source = None
        if data.get("source_review") is not None:
            source = Review.objects.filter(pk=data["source_review"], capture=capture,
                                           status="submitted").first()
            if source is None:
                raise Invalid(f"source_review: review {data['source_review']} is not a "
                              "submitted review of this capture")
        do_save_gold(capture, request.user, data["cuts"], data["labels"], data["version"], source,
                     data.get("attributes"))
        return Response(AdjudicationSerializer(adjudication_body(capture)).data)


urlpatterns = [
    path("captures/<int:pk>/adjudication/", AdjudicationView.as_view(), name="api-adjudication"),
]
