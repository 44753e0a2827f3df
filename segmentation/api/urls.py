from django.urls import path
from drf_spectacular.views import SpectacularAPIView, SpectacularSwaggerSplitView
from rest_framework.routers import SimpleRouter

from cutroom.accounts import api as accounts_api
from segmentation.api import assignments, health, invitations, library, reviews, team
from segmentation.api.captures import CaptureViewSet
from segmentation.api.projects import MethodsView, MeView, ProjectViewSet

router = SimpleRouter()
router.register("projects", ProjectViewSet, basename="project")
router.register("captures", CaptureViewSet, basename="capture")

review = "captures/<int:pk>/review/"
urlpatterns = [
    *accounts_api.urlpatterns,
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
    path("captures/<int:pk>/reviews/", reviews.AllReviewsView.as_view(), name="api-reviews"),
    *library.urlpatterns,
    *invitations.urlpatterns,
    *assignments.urlpatterns,
    *team.urlpatterns,
    *health.urlpatterns,
    *router.urls,
]
