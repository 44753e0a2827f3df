"""Failed and successful sign-ins, whichever view checked the password, feed the
throttle: Django sends ``user_login_failed`` from ``authenticate`` (the login page, the
admin's login page and the token endpoint all call it with the request)."""

from django.contrib.auth.signals import user_logged_in, user_login_failed
from django.dispatch import receiver

from cutroom.accounts import throttle


@receiver(user_login_failed)
def count_failure(sender, credentials, request=None, **kwargs):
    if request is not None:
        throttle.record_failure(request, throttle.username_of(credentials))


@receiver(user_logged_in)
def clear_failures(sender, request, user, **kwargs):
    throttle.forget_failures(user.get_username())
