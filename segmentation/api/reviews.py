"""The caller's review of a capture (cuts, labels, submit, audit log) and, for reviewers,
everyone's reviews. Each view checks the request's shape and calls one service."""

from django.shortcuts import get_object_or_404
from drf_spectacular.utils import extend_schema
from rest_framework.exceptions import PermissionDenied
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation import services
from segmentation.api.common.params import body
from segmentation.api.common.serializers.reviews import (
    ChangeCutSerializer,
    EventSerializer,
    InsertCutSerializer,
    LabelSegmentSerializer,
    RestoreSerializer,
    ReviewPageSerializer,
    ReviewSerializer,
    SuggestionsSerializer,
    VersionSerializer,
)
from segmentation.errors import Invalid
from segmentation.queries.access import capture_for
from segmentation.services import history
from segmentation.services.adaptation import adaptation_summary
from segmentation.services.reviews import catch_up, started_review
from segmentation.similar import suggestions


class OwnReviewView(APIView):
    """Base: the caller's own review of capture ``pk`` (a write starts it on first use)."""

    # An edit's answer is the review as the edit left it, without the adaptation summary
    # of the review page (GET): no edit changes it, and it costs four queries.

    def review(self, pk):
        review = started_review(self.request.user, pk)
        if review is None:
            return services.get_or_create_review(capture_for(self.request.user, pk), self.request.user)
        catch_up(review)
        return review

    def reply(self, review, status=200):
        # The services keep ``review`` as the database has it after their write.
        return Response(ReviewSerializer(review).data, status=status)


class ReviewView(OwnReviewView):
    @extend_schema(responses=ReviewPageSerializer)
    def get(self, request, pk):
        """The caller's review, with what the review page says about adaptation; before
        they start one, the review they would start (``id`` null; its cuts have no ids
        yet), which is not stored: reading never writes. A write based on it sends
        version 1, the version the review starts at."""
        capture = capture_for(request.user, pk)
        review = services.own_review(capture, request.user)
        if review is None:
            return Response(unstarted_review(capture, request.user))
        return Response(ReviewPageSerializer(review).data)

    @extend_schema(request=None, responses=ReviewSerializer)
    def post(self, request, pk):
        """Start the caller's review (or return it if started)."""
        return self.reply(self.review(pk))


def unstarted_review(capture, user):
    """A review as ``user`` would start it now: the latest finished run's candidates."""
    run = capture.latest_finished_run()
    candidates = sorted(run.candidates, key=lambda c: c["frame"]) if run else []
    cuts = [{"id": None, "origin": "candidate", "fate": "pending", "candidate_frame": c["frame"],
             "frame": c["frame"], "confidence": c["confidence"]} for c in candidates]
    bounds = [0, *[c["frame"] for c in candidates], capture.n_frames or 0]
    return {
        "id": None, "capture": capture.pk, "annotator": {"id": user.pk, "username": user.username},
        "run": run.pk if run else None, "status": "not_started", "version": 1,
        "return_comment": "", "cuts": cuts,
        "segments": [{"index": i, "start": a, "stop": b, "label": None, "attributes": {}}
                     for i, (a, b) in enumerate(zip(bounds[:-1], bounds[1:], strict=True))],
        "adaptation": adaptation_summary(run, capture.project_id, user),
    }


class SuggestionsView(APIView):
    @extend_schema(responses=SuggestionsSerializer)
    def get(self, request, pk):
        """Suggested labels of the caller's unlabelled segments, as far as computed."""
        capture = capture_for(request.user, pk)
        services.own_review(capture, request.user)  # NotReady before ingest finished
        return Response(suggestions.for_review(capture, request.user))


class CutsView(OwnReviewView):
    @extend_schema(request=InsertCutSerializer, responses=ReviewSerializer)
    def post(self, request, pk):
        data = body(request, InsertCutSerializer)
        review = self.review(pk)
        return self.reply(services.do_insert_cut(review, request.user, data["frame"], data["version"]), 201)


class CutView(OwnReviewView):
    @extend_schema(request=ChangeCutSerializer, responses=ReviewSerializer)
    def patch(self, request, pk, cut_id):
        data = body(request, ChangeCutSerializer)
        review = self.review(pk)
        cut = get_object_or_404(review.cuts, pk=cut_id)
        services.do_change_cut(review, request.user, cut, **data)
        return self.reply(review)


class SegmentView(OwnReviewView):
    @extend_schema(request=LabelSegmentSerializer, responses=ReviewSerializer)
    def patch(self, request, pk, index):
        data = body(request, LabelSegmentSerializer)
        review = self.review(pk)
        services.do_label_segment(review, request.user, index, data["label"], data["version"])
        return self.reply(review)


class SubmitView(OwnReviewView):
    @extend_schema(request=VersionSerializer, responses=ReviewSerializer)
    def post(self, request, pk):
        data = body(request, VersionSerializer)
        review = self.review(pk)
        return self.reply(services.do_submit_review(review, request.user, data["version"]))


class EventsView(OwnReviewView):
    @extend_schema(responses=EventSerializer(many=True))
    def get(self, request, pk):
        review = services.own_review(capture_for(request.user, pk), request.user)
        events = review.events.select_related("user") if review else []
        return Response(EventSerializer(events, many=True).data)


class UndoView(APIView):
    """Undo (or, as RedoView, redo) the caller's last step, as the review's log has it:
    undo survives a reload. The answer is the review as restored; the restore is an event."""

    verb = "undo"

    @extend_schema(request=VersionSerializer, responses=ReviewSerializer)
    def post(self, request, pk):
        data = body(request, VersionSerializer)
        review = started_review(request.user, pk)
        if review is None:
            capture_for(request.user, pk)  # 404 for a capture the caller does not see
            raise Invalid(f"{self.verb}: you have not started a review of capture {pk}")
        step = history.do_undo if self.verb == "undo" else history.do_redo
        return Response(ReviewSerializer(step(review, request.user, data["version"])).data)


class RedoView(UndoView):
    verb = "redo"


def review_for(user, pk, review_id):
    """Review ``review_id`` of capture ``pk`` for its annotator or the project's reviewers
    and admins; 404 for a capture the caller does not see, 403 for another annotator."""
    capture = capture_for(user, pk)
    review = get_object_or_404(capture.reviews, pk=review_id)
    if review.annotator_id != user.pk and not capture.project.can_see_all_reviews(user):
        raise PermissionDenied("Only the review's annotator and the project's reviewers and admins see its history.")
    review.capture = capture
    return review


class ReviewEventsView(APIView):
    @extend_schema(responses=EventSerializer(many=True))
    def get(self, request, pk, review_id):
        """The activity log of one review (its annotator, reviewers, admins)."""
        review = review_for(request.user, pk, review_id)
        return Response(EventSerializer(review.events.select_related("user"), many=True).data)


class RestoreView(APIView):
    @extend_schema(request=RestoreSerializer, responses=ReviewSerializer)
    def post(self, request, pk, review_id):
        """Restore the review as it was right after one of its events; the restore is an
        event itself (so it can be undone). A stale ``version`` is refused (409)."""
        data = body(request, RestoreSerializer)
        review = review_for(request.user, pk, review_id)
        history.do_restore_review(review, request.user, data["event"], data["version"])
        return Response(ReviewSerializer(review).data)


class AllReviewsView(APIView):
    @extend_schema(responses=ReviewSerializer(many=True))
    def get(self, request, pk):
        capture = capture_for(request.user, pk)
        if not capture.project.can_see_all_reviews(request.user):
            raise PermissionDenied("Only the project's reviewers and admins see every review.")
        reviews = capture.reviews.select_related("annotator").prefetch_related("cuts")
        return Response(ReviewSerializer(reviews, many=True).data)
