"""The caller's review of a capture (cuts, labels, submit, audit log) and, for reviewers,
everyone's reviews. Each view checks the request's shape and calls one service."""

from django.shortcuts import get_object_or_404
from drf_spectacular.utils import extend_schema
from rest_framework.exceptions import PermissionDenied
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation import services
from segmentation.api.captures import capture_for
from segmentation.api.serializers import (
    ChangeCutSerializer,
    EventSerializer,
    InsertCutSerializer,
    LabelSegmentSerializer,
    ReviewSerializer,
    VersionSerializer,
)


class OwnReviewView(APIView):
    """Base: the caller's own review of capture ``pk`` (created on first use)."""

    def review(self, pk):
        return services.get_or_create_review(capture_for(self.request.user, pk), self.request.user)

    def body(self, serializer_class):
        serializer = serializer_class(data=self.request.data)
        serializer.is_valid(raise_exception=True)
        return serializer.validated_data

    def reply(self, review, status=200):
        review.refresh_from_db()
        return Response(ReviewSerializer(review).data, status=status)


class ReviewView(OwnReviewView):
    @extend_schema(responses=ReviewSerializer)
    def get(self, request, pk):
        return self.reply(self.review(pk))

    @extend_schema(request=None, responses=ReviewSerializer)
    def post(self, request, pk):
        return self.reply(self.review(pk))


class CutsView(OwnReviewView):
    @extend_schema(request=InsertCutSerializer, responses=ReviewSerializer)
    def post(self, request, pk):
        data = self.body(InsertCutSerializer)
        review = self.review(pk)
        return self.reply(services.do_insert_cut(review, request.user, data["frame"], data["version"]), 201)


class CutView(OwnReviewView):
    @extend_schema(request=ChangeCutSerializer, responses=ReviewSerializer)
    def patch(self, request, pk, cut_id):
        data = self.body(ChangeCutSerializer)
        review = self.review(pk)
        cut = get_object_or_404(review.cuts, pk=cut_id)
        services.do_change_cut(review, request.user, cut, **data)
        return self.reply(review)


class SegmentView(OwnReviewView):
    @extend_schema(request=LabelSegmentSerializer, responses=ReviewSerializer)
    def patch(self, request, pk, index):
        data = self.body(LabelSegmentSerializer)
        review = self.review(pk)
        services.do_label_segment(review, request.user, index, data["label"], data["version"])
        return self.reply(review)


class SubmitView(OwnReviewView):
    @extend_schema(request=VersionSerializer, responses=ReviewSerializer)
    def post(self, request, pk):
        data = self.body(VersionSerializer)
        review = self.review(pk)
        return self.reply(services.do_submit_review(review, request.user, data["version"]))


class EventsView(OwnReviewView):
    @extend_schema(responses=EventSerializer(many=True))
    def get(self, request, pk):
        events = self.review(pk).events.select_related("user")
        return Response(EventSerializer(events, many=True).data)


class AllReviewsView(APIView):
    @extend_schema(responses=ReviewSerializer(many=True))
    def get(self, request, pk):
        capture = capture_for(request.user, pk)
        if not capture.project.can_see_all_reviews(request.user):
            raise PermissionDenied("Only the project's reviewers and admins see every review.")
        reviews = capture.reviews.select_related("annotator").prefetch_related("cuts")
        return Response(ReviewSerializer(reviews, many=True).data)
