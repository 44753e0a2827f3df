"""Sign-in pages: Django's login views behind the sign-in throttle, and the form that
replaces a one-time password."""

import math
from functools import wraps

from django.contrib.auth import update_session_auth_hash
from django.contrib.auth.decorators import login_required
from django.contrib.auth.forms import SetPasswordForm
from django.shortcuts import redirect, render
from django.utils.http import url_has_allowed_host_and_scheme

from cutroom.accounts import middleware, passwords, throttle


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


class NewPasswordForm(SetPasswordForm):
    """Django's form (both fields equal, the password validators), and not the one-time
    password again."""

    def clean(self):
        cleaned = super().clean()
        password = cleaned.get("new_password1")
        if password and self.user.check_password(password):
            self.add_error("new_password1", "The new password must differ from the one-time password.")
        return cleaned


@login_required
def new_password(request):
    """GET: the form; POST: the person's own password replaces the one-time one, this
    session stays signed in, and they go on to the page they asked for."""
    target = request.GET.get("next", "/")
    if not url_has_allowed_host_and_scheme(target, {request.get_host()}, request.is_secure()):
        target = "/"
    if not request.session.get(middleware.SESSION_KEY):
        return redirect(target)
    form = NewPasswordForm(request.user, request.POST or None)
    if request.method == "POST" and form.is_valid():
        passwords.choose(request.user, form.cleaned_data["new_password1"])
        update_session_auth_hash(request, request.user)
        del request.session[middleware.SESSION_KEY]
        return redirect(target)
    return render(request, "registration/new_password.html", {"form": form})
