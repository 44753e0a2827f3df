"""Sign-in and sign-out pages: Django's login views behind the sign-in throttle, and a
sign-out that only a POST with the CSRF token does."""

import math
from functools import wraps

from django.conf import settings
from django.contrib.auth import logout
from django.shortcuts import redirect, render
from django.views.decorators.http import require_POST

from accounts import throttle


def throttled_sign_in(view):
    """Refuse a sign-in POST with 429 while its username or address is throttled.

    The password is not checked then. An attempt let through is counted as a failure
    until it succeeds (``throttle.admit``; ``signals.clear_failures`` takes it back).
    """

    @wraps(view)
    def wrapper(request, *args, **kwargs):
        if request.method == "POST":
            wait = throttle.admit(request, throttle.username_of(request.POST))
            if wait:
                return too_many_attempts(request, wait)
        return view(request, *args, **kwargs)

    return wrapper


def too_many_attempts(request, wait):
    context = {"minutes": math.ceil(wait / 60), "back": request.get_full_path()}
    response = render(request, "registration/throttled.html", context, status=429)
    response["Retry-After"] = str(wait)
    return response


@require_POST
def logout_view(request):
    # POST only (with the CSRF token, checked by the middleware): a link or an image on
    # another page must not be able to sign anyone out.
    logout(request)
    return redirect(settings.LOGOUT_REDIRECT_URL)
