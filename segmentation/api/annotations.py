"""Existing annotations in and out of a capture.

- ``POST /api/captures/{id}/annotations/inspect/`` (multipart: ``file``, ``format``,
  ``source``, ``unit``, ``target``): what the file holds — its sources (ELAN tiers, Label
  Studio annotations, CSV annotators), the chosen source's segments and which labels the
  project lacks. Writes nothing.
- ``POST /api/captures/{id}/annotations/import/`` (the same, with ``mapping`` and
  ``version``): into the caller's own review (``target=review``, the review's version) or
  the gold version (``target=gold``, reviewers and admins, the gold version or 0).
- ``GET /api/captures/{id}/annotations/export.{csv|eaf|labelstudio}?source=mine|gold|all|<review id>``

Annotators import into their own review only; gold and other people's reviews are for the
project's reviewers and admins (403 for an annotator, 404 for anyone outside the project).
"""

from django.http import HttpResponse
from django.shortcuts import get_object_or_404
from django.urls import path
from drf_spectacular.utils import OpenApiParameter, extend_schema
from rest_framework.parsers import FormParser, MultiPartParser
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation import services
from segmentation.api.common.params import body
from segmentation.api.common.serializers.annotations import (
    ImportedSerializer,
    ImportSerializer,
    InspectionSerializer,
    InspectSerializer,
)
from segmentation.api.common.serializers.reviews import ReviewSerializer
from segmentation.errors import Invalid, Missing, NotAllowed
from segmentation.files import annotation_exports as exports
from segmentation.models import Adjudication
from segmentation.queries.access import capture_for, staff_capture
from segmentation.services import annotations
from segmentation.services.reviews import catch_up, started_review


def target_capture(user, pk, target):
    """The capture, if the caller may import into ``target`` of it."""
    return staff_capture(user, pk) if target == "gold" else capture_for(user, pk)


def parsed(capture, data):
    return annotations.Parsed(capture, data["file"], data.get("format") or None,
                              data.get("source") or None, data["unit"])


class InspectView(APIView):
    parser_classes = [MultiPartParser, FormParser]

    @extend_schema(request={"multipart/form-data": InspectSerializer},
                   responses=InspectionSerializer)
    def post(self, request, pk):
        data = body(request, InspectSerializer)
        capture = target_capture(request.user, pk, data["target"])
        if data["target"] == "review":
            services.own_review(capture, request.user)  # may they start it at all?
        return Response(annotations.inspect(capture, parsed(capture, data)))


class ImportView(APIView):
    parser_classes = [MultiPartParser, FormParser]

    @extend_schema(request={"multipart/form-data": ImportSerializer},
                   responses=ImportedSerializer)
    def post(self, request, pk):
        """Import into the caller's review or into the gold version; the answer is the one
        imported into."""
        data = body(request, ImportSerializer)
        capture = target_capture(request.user, pk, data["target"])
        mapping = annotations.parse_mapping(data.get("mapping"))
        if data["target"] == "gold":
            gold = annotations.do_import_gold(capture, request.user, parsed(capture, data),
                                              mapping, data["version"])
            return Response({"review": None, "gold": {
                "cuts": gold.cuts, "labels": gold.label_names(), "version": gold.version}})
        file = parsed(capture, data)
        # The file and its labels are checked before a review is started for it.
        annotations.mapped_spans(capture, file, mapping)
        review = started_review(request.user, pk)
        if review is None:
            review = services.get_or_create_review(capture, request.user)
        else:
            catch_up(review)
        annotations.do_import_review(review, request.user, file, mapping, data["version"])
        return Response({"review": ReviewSerializer(review).data, "gold": None})


class ExportView(APIView):
    @extend_schema(responses={(200, "application/octet-stream"): bytes}, parameters=[
        OpenApiParameter("source", str, description="mine (default), gold, all (reviewers "
                         "and admins) or a review id")])
    def get(self, request, pk, form):
        if form not in exports.FORMATS:
            raise Missing(f"No export as {form!r}; choose csv, eaf or labelstudio.")
        capture = capture_for(request.user, pk)
        tracks = export_tracks(request.user, capture, request.query_params.get("source") or "mine")
        data, content_type, name = exports.render(form, tracks, exports.take_stem(capture.name))
        response = HttpResponse(data, content_type=content_type)
        response["Content-Disposition"] = f'attachment; filename="{name}"'
        return response


def export_tracks(user, capture, source):
    """The tracks ``source`` names: the caller's review, the gold version, every review and
    gold (staff), or one review (its annotator or staff)."""
    staff = capture.project.can_see_all_reviews(user)
    gold = Adjudication.objects.filter(capture=capture).first()
    if source == "mine":
        review = services.own_review(capture, user)
        if review is None:
            raise Invalid(f"source: you have not started a review of capture {capture.pk}")
        return [exports.review_track(review)]
    if source == "gold":
        if gold is None:
            raise Invalid(f"source: capture {capture.pk} has no gold version yet")
        return [exports.gold_track(gold)]
    if source == "all":
        if not staff:
            raise NotAllowed("Only the project's reviewers and admins export every review.")
        reviews = capture.reviews.select_related("annotator").order_by("id")
        return [exports.review_track(r) for r in reviews] + ([exports.gold_track(gold)] if gold else [])
    if not source.isdigit():
        raise Invalid(f"source: must be mine, gold, all or a review id, got {source[:40]!r}")
    review = get_object_or_404(capture.reviews.select_related("annotator"), pk=int(source))
    if review.annotator_id != user.pk and not staff:
        raise NotAllowed("Only the review's annotator and the project's reviewers and admins "
                         "export it.")
    review.capture = capture
    return [exports.review_track(review)]


base = "captures/<int:pk>/annotations/"
urlpatterns = [
    path(base + "inspect/", InspectView.as_view(), name="api-annotations-inspect"),
    path(base + "import/", ImportView.as_view(), name="api-annotations-import"),
    path(base + "export.<str:form>", ExportView.as_view(), name="api-annotations-export"),
]
