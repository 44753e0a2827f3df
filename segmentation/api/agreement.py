"""``GET /api/captures/{id}/agreement/?tolerance=0.25``: how a capture's submitted reviews
agree (reviewers and admins; an annotator is told why not, an outsider gets 404)."""

from django.urls import path
from drf_spectacular.utils import OpenApiParameter, extend_schema
from rest_framework import serializers
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation.api.common.params import float_param
from segmentation.api.common.serializers.base import UserRefSerializer
from segmentation.queries.access import staff_capture
from segmentation.services import agreement


class AgreementReviewSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    annotator = UserRefSerializer()
    cuts = serializers.IntegerField(help_text="How many cuts it keeps")
    submitted_at = serializers.DateTimeField(allow_null=True)


class PairSideSerializer(serializers.Serializer):
    review = serializers.IntegerField()
    annotator = serializers.CharField()


class PairSerializer(serializers.Serializer):
    a = PairSideSerializer()
    b = PairSideSerializer()
    precision = serializers.FloatField(allow_null=True)
    recall = serializers.FloatField(allow_null=True)
    f1 = serializers.FloatField(allow_null=True)
    matched = serializers.IntegerField()
    kappa = serializers.FloatField(allow_null=True)


class LabelMeasureSerializer(serializers.Serializer):
    method = serializers.ChoiceField(choices=["cohen_kappa", "krippendorff_alpha"], allow_null=True)
    value = serializers.FloatField(allow_null=True)


class LabelOverlapSerializer(serializers.Serializer):
    label = serializers.CharField()
    overlap = serializers.FloatField(allow_null=True)
    frames = serializers.IntegerField()


class AgreementSerializer(serializers.Serializer):
    """Agreement of a capture's submitted reviews (measures null where undefined)."""

    capture = serializers.IntegerField()
    tolerance_s = serializers.FloatField()
    n_reviews = serializers.IntegerField()
    reviews = AgreementReviewSerializer(many=True)
    pairs = PairSerializer(many=True)
    boundary_f1 = serializers.FloatField(allow_null=True)
    labels = LabelMeasureSerializer()
    alpha = serializers.FloatField(allow_null=True)
    per_label = LabelOverlapSerializer(many=True)


class AgreementView(APIView):
    @extend_schema(responses=AgreementSerializer,
                   parameters=[OpenApiParameter("tolerance", float, description="seconds (default 0.25)")])
    def get(self, request, pk):
        capture = staff_capture(request.user, pk)
        tolerance = float_param(request, "tolerance", 0, 10)
        tolerance = agreement.DEFAULT_TOLERANCE_S if tolerance is None else tolerance
        return Response(AgreementSerializer(agreement.capture_agreement(capture, tolerance)).data)


urlpatterns = [
    path("captures/<int:pk>/agreement/", AgreementView.as_view(), name="api-agreement"),
]
