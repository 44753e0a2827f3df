"""Signed in with a one-time password, a person chooses their own before anything else.

The sign-in (``signals.note_one_time_password``) marks the session; while it is marked,
every page leads to the form that asks for a new password and the API refuses with a 403
saying so. The mark lives in the session, so other requests cost no query.
"""

from urllib.parse import quote

from django.http import JsonResponse
from django.shortcuts import redirect

SESSION_KEY = "cutroom_one_time_password"
NEW_PASSWORD_URL = "/password/new/"
# What a person may still reach: the form itself, signing out, the tab's icon.
OPEN_PATHS = (NEW_PASSWORD_URL, "/logout/", "/favicon.svg", "/favicon.ico")
REFUSAL = ("You signed in with a one-time password: choose a new password first, at "
           f"{NEW_PASSWORD_URL}")


def new_password_first(get_response):
    def middleware(request):
        if request.path in OPEN_PATHS or not request.session.get(SESSION_KEY):
            return get_response(request)
        if request.path.startswith("/api/"):
            return JsonResponse({"detail": REFUSAL}, status=403)
        return redirect(f"{NEW_PASSWORD_URL}?next={quote(request.get_full_path(), safe='/')}")

    return middleware
