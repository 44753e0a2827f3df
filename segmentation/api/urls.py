from django.urls import path
from drf_spectacular.views import SpectacularAPIView, SpectacularSwaggerSplitView
from rest_framework.routers import SimpleRouter

from segmentation.api import (
    adjudication,
    agreement,
    annotations,
    assignments,
    attributes,
    comments,
    dashboard,
    health,
    invitations,
    reviews,
    segments,
    similar,
    team,
    videos,
)
from segmentation.api.captures import CaptureViewSet
from segmentation.api.projects import MethodsView, MeView, ProjectViewSet

router = SimpleRouter()
router.register("projects", ProjectViewSet, basename="project")
router.register("captures", CaptureViewSet, basename="capture")

review = "captures/<int:pk>/review/"
urlpatterns = [
    path("me/", MeView.as_view(), name="api-me"),
    path("methods/", MethodsView.as_view(), name="api-methods"),
    path("schema/", SpectacularAPIView.as_view(), name="api-schema"),
    # The split view serves its start-up script as a file, which the CSP allows.
    path("docs/", SpectacularSwaggerSplitView.as_view(url_name="api-schema"), name="api-docs"),
    path(review, reviews.ReviewView.as_view(), name="api-review"),
    path(review + "cuts/", reviews.CutsView.as_view(), name="api-review-cuts"),
    path(review + "cuts/<int:cut_id>/", reviews.CutView.as_view(), name="api-review-cut"),
    path(review + "segments/<int:index>/", reviews.SegmentView.as_view(), name="api-review-segment"),
    path(review + "submit/", reviews.SubmitView.as_view(), name="api-review-submit"),
    path(review + "events/", reviews.EventsView.as_view(), name="api-review-events"),
    path(review + "suggestions/", reviews.SuggestionsView.as_view(), name="api-review-suggestions"),
    path(review + "undo/", reviews.UndoView.as_view(), name="api-review-undo"),
    path(review + "redo/", reviews.RedoView.as_view(), name="api-review-redo"),
    path("captures/<int:pk>/reviews/<int:review_id>/events/", reviews.ReviewEventsView.as_view(),
         name="api-review-events-of"),
    path("captures/<int:pk>/reviews/<int:review_id>/restore/", reviews.RestoreView.as_view(),
         name="api-review-restore"),
    path("captures/<int:pk>/reviews/", reviews.AllReviewsView.as_view(), name="api-reviews"),
    *comments.urlpatterns,
    *attributes.urlpatterns,
    *segments.urlpatterns,
    *similar.urlpatterns,
    *agreement.urlpatterns,
    *adjudication.urlpatterns,
    *annotations.urlpatterns,
    *dashboard.urlpatterns,
    *invitations.urlpatterns,
    *assignments.urlpatterns,
    *team.urlpatterns,
    *health.urlpatterns,
    *videos.urlpatterns,
    *router.urls,
]
