"""Comments on reviews (``segmentation.queries.comments`` says who reads which):

- ``GET /api/captures/{id}/comments/``: every comment the caller reads on the capture;
- ``GET|POST /api/captures/{id}/reviews/{review}/comments/``: one review's, or a new one;
- ``POST /api/captures/{id}/review/comments/``: a new one on the caller's own review
  (started by it, like a first edit);
- ``PATCH /api/captures/{id}/reviews/{review}/comments/{comment}/``: resolve a thread.
"""

from django.shortcuts import get_object_or_404
from django.urls import path
from drf_spectacular.utils import extend_schema
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation import services
from segmentation.api.common.params import body
from segmentation.api.common.serializers.comments import (
    CommentSerializer,
    NewCommentSerializer,
    ResolveSerializer,
)
from segmentation.queries.access import capture_for
from segmentation.queries.comments import comment_review, readable_reviews, threads
from segmentation.services.comments import do_add_comment, do_resolve_comment


def created(review, user, data):
    comment = do_add_comment(review, user, data["text"], frame=data.get("frame"),
                             cut=data.get("cut"), segment=data.get("segment"),
                             parent=data.get("parent"))
    return Response(CommentSerializer(threads([review.pk]).get(pk=comment.pk)).data, status=201)


class CaptureCommentsView(APIView):
    @extend_schema(responses=CommentSerializer(many=True))
    def get(self, request, pk):
        capture = capture_for(request.user, pk)
        return Response(CommentSerializer(threads(readable_reviews(request.user, capture)), many=True).data)


class ReviewCommentsView(APIView):
    @extend_schema(responses=CommentSerializer(many=True))
    def get(self, request, pk, review_id):
        review = comment_review(request.user, pk, review_id)
        return Response(CommentSerializer(threads([review.pk]), many=True).data)

    @extend_schema(request=NewCommentSerializer, responses={201: CommentSerializer})
    def post(self, request, pk, review_id):
        data = body(request, NewCommentSerializer)
        return created(comment_review(request.user, pk, review_id, write=True), request.user, data)


class OwnReviewCommentsView(APIView):
    @extend_schema(request=NewCommentSerializer, responses={201: CommentSerializer})
    def post(self, request, pk):
        """A comment on the caller's own review, which it starts if they had not."""
        data = body(request, NewCommentSerializer)
        review = services.get_or_create_review(capture_for(request.user, pk), request.user)
        return created(review, request.user, data)


class CommentView(APIView):
    @extend_schema(request=ResolveSerializer, responses=CommentSerializer)
    def patch(self, request, pk, review_id, comment_id):
        data = body(request, ResolveSerializer)
        review = comment_review(request.user, pk, review_id, write=True)
        comment = get_object_or_404(review.comments, pk=comment_id)
        do_resolve_comment(comment, request.user, data["resolved"])
        return Response(CommentSerializer(threads([review.pk]).get(pk=comment.pk)).data)


urlpatterns = [
    path("captures/<int:pk>/comments/", CaptureCommentsView.as_view(), name="api-comments"),
    path("captures/<int:pk>/review/comments/", OwnReviewCommentsView.as_view(),
         name="api-review-comments-own"),
    path("captures/<int:pk>/reviews/<int:review_id>/comments/", ReviewCommentsView.as_view(),
         name="api-review-comments"),
    path("captures/<int:pk>/reviews/<int:review_id>/comments/<int:comment_id>/",
         CommentView.as_view(), name="api-review-comment"),
]
