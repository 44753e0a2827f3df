"""``GET /api/captures/{id}/agreement/?tolerance=0.25``: how a capture's submitted reviews
agree (reviewers and admins; an annotator is told why not, an outsider gets 404)."""

from django.urls import path
from drf_spectacular.utils import OpenApiParameter, extend_schema
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation.api.common.params import float_param
from segmentation.api.common.serializers.agreement import AgreementSerializer
from segmentation.queries.access import staff_capture
from segmentation.services import agreement


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
