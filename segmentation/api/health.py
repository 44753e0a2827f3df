"""``GET /api/health/``: the service's health for monitoring (no sign-in: a monitor has no
account). 200 when every check passes, 503 naming the failing ones; docs/operations.md lists
the checks. It says what works, never who or what is stored."""

from django.urls import path
from drf_spectacular.utils import extend_schema
from rest_framework.permissions import AllowAny
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation.services import health


class HealthView(APIView):
    authentication_classes = []
    permission_classes = [AllowAny]

    @extend_schema(exclude=True)  # for monitors, not for the front end's typed client
    def get(self, request):
        ok, checks = health.report()
        failing = [name for name, check in checks.items() if not check["ok"]]
        body = {"status": "ok" if ok else "failing", "failing": failing, "checks": checks}
        return Response(body, status=200 if ok else 503)


urlpatterns = [path("health/", HealthView.as_view(), name="api-health")]
