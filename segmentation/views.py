"""Pages outside the API: the single-page app's index and its icon (signing in and out is
``accounts.views``)."""

from django.conf import settings
from django.contrib.auth.decorators import login_required
from django.http import HttpResponse
from django.shortcuts import render
from django.views.decorators.csrf import ensure_csrf_cookie


@login_required
@ensure_csrf_cookie  # the front end sends it back as X-CSRFToken on writes
def app(request, path=""):
    """The built front end's index.html; every client-side route gets the same page."""
    index = settings.FRONTEND_DIST / "index.html"
    if not index.is_file():
        context = {"dist": settings.FRONTEND_DIST}
        return render(request, "segmentation/not_built.html", context, status=503)
    return HttpResponse(index.read_text(encoding="utf-8"))


# The app's icon (a cut between two segments), served at the address browsers ask for
# by themselves (/favicon.ico) as well as the one the pages link to.
FAVICON = (
    '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 32 32">'
    '<rect width="32" height="32" rx="6" fill="#12161c"/>'
    '<rect x="4" y="11" width="11" height="10" rx="2" fill="#4fc3f7"/>'
    '<rect x="17" y="11" width="11" height="10" rx="2" fill="#7ee2a8"/>'
    '<rect x="15" y="5" width="2" height="22" fill="#ffd666"/></svg>'
)


def favicon(request):
    response = HttpResponse(FAVICON, content_type="image/svg+xml")
    response["Cache-Control"] = "public, max-age=86400"
    return response
