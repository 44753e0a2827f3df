"""Segment attributes:

- ``GET|POST /api/projects/{id}/attributes/``: the project's schema (any member reads it;
  admins add);
- ``PATCH|DELETE /api/projects/{id}/attributes/{attribute}/``: change or delete one (admins;
  nothing stored is lost: see ``services.attributes``);
- ``PATCH /api/captures/{id}/review/segments/{index}/attributes/``: set a value on a segment
  of the caller's own review (a review edit: ``version`` as for labels).
"""

from django.shortcuts import get_object_or_404
from django.urls import path
from drf_spectacular.utils import extend_schema
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation import services
from segmentation.api.common.params import body
from segmentation.api.common.serializers.attributes import (
    AttributeChangeSerializer,
    AttributeSerializer,
    SetAttributeSerializer,
)
from segmentation.api.common.serializers.reviews import ReviewSerializer
from segmentation.errors import NotAllowed
from segmentation.queries.access import capture_for, project_for
from segmentation.services import attributes
from segmentation.services.review_attributes import do_set_attribute
from segmentation.services.reviews import catch_up, started_review


def shown(attribute):
    return {"id": attribute.pk, "name": attribute.name, "kind": attribute.kind,
            "options": attribute.options, "hotkey": attribute.hotkey,
            "position": attribute.position, "in_use": attributes.in_use(attribute)}


def admin_project(user, pk):
    project = project_for(user, pk)
    if not project.can_manage(user):
        raise NotAllowed("Only the project's admins change its attributes.")
    return project


class AttributesView(APIView):
    @extend_schema(responses=AttributeSerializer(many=True))
    def get(self, request, pk):
        project = project_for(request.user, pk)
        return Response(AttributeSerializer([shown(a) for a in project.attributes.all()], many=True).data)

    @extend_schema(request=AttributeSerializer, responses={201: AttributeSerializer})
    def post(self, request, pk):
        project = admin_project(request.user, pk)
        data = body(request, AttributeSerializer)
        attribute = attributes.do_add_attribute(project, data["name"], data["kind"],
                                                data.get("options"), data.get("hotkey"))
        return Response(AttributeSerializer(shown(attribute)).data, status=201)


class AttributeView(APIView):
    @extend_schema(request=AttributeChangeSerializer, responses=AttributeSerializer)
    def patch(self, request, pk, attribute_id):
        project = admin_project(request.user, pk)
        attribute = get_object_or_404(project.attributes, pk=attribute_id)
        fields = body(request, AttributeChangeSerializer)
        return Response(AttributeSerializer(shown(attributes.do_change_attribute(attribute, **fields))).data)

    @extend_schema(request=None, responses={204: None})
    def delete(self, request, pk, attribute_id):
        project = admin_project(request.user, pk)
        attributes.do_delete_attribute(get_object_or_404(project.attributes, pk=attribute_id))
        return Response(status=204)


class SegmentAttributeView(APIView):
    @extend_schema(request=SetAttributeSerializer, responses=ReviewSerializer)
    def patch(self, request, pk, index):
        data = body(request, SetAttributeSerializer)
        review = started_review(request.user, pk)
        if review is None:
            review = services.get_or_create_review(capture_for(request.user, pk), request.user)
        else:
            catch_up(review)
        do_set_attribute(review, request.user, index, data["name"], data["value"], data["version"])
        return Response(ReviewSerializer(review).data)


urlpatterns = [
    path("projects/<int:pk>/attributes/", AttributesView.as_view(), name="api-attributes"),
    path("projects/<int:pk>/attributes/<int:attribute_id>/", AttributeView.as_view(),
         name="api-attribute"),
    path("captures/<int:pk>/review/segments/<int:index>/attributes/", SegmentAttributeView.as_view(),
         name="api-review-segment-attributes"),
]
