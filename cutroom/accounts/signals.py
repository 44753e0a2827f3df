"""Failed and successful sign-ins, whichever view checked the password, feed the
throttle: Django sends ``user_login_failed`` from ``authenticate`` (the login page, the
admin's login page and the token endpoint all call it with the request). A new password revokes the account's API tokens, and a
new account's username is checked however the account is made."""

from django.conf import settings
from django.contrib.auth.signals import user_logged_in, user_login_failed
from django.db.models.signals import post_save, pre_save
from django.dispatch import receiver

from cutroom.accounts import middleware, passwords, throttle
from cutroom.accounts.models import ApiToken
from segmentation import usernames


@receiver(user_login_failed)
def count_failure(sender, credentials, request=None, **kwargs):
    if request is not None:
        throttle.record_failure(request, throttle.username_of(credentials))


@receiver(user_logged_in)
def clear_failures(sender, request, user, **kwargs):
    throttle.succeeded(request, user.get_username())


@receiver(user_logged_in)
def note_one_time_password(sender, request, user, **kwargs):
    """A sign-in with a one-time password leads to choosing a new one (``middleware``)."""
    if passwords.is_one_time(user):
        request.session[middleware.SESSION_KEY] = True


@receiver(post_save, sender=settings.AUTH_USER_MODEL)
def revoke_tokens_on_new_password(sender, instance, created, **kwargs):
    """A new password revokes the account's API tokens, however it was set (the API, the
    admin, ``manage.py changepassword``): whoever took the old password may hold one.
    Sessions end on their own, since Django signs each with the password's hash."""
    # set_password() leaves the raw password on the instance until save() has run.
    if not created and getattr(instance, "_password", None) is not None:
        ApiToken.objects.filter(user=instance).delete()


@receiver(pre_save, sender=settings.AUTH_USER_MODEL)
def check_new_username(sender, instance, raw=False, **kwargs):
    """Every new account's username goes through ``usernames`` (``createsuperuser`` and
    scripts too; the forms and the API check first, to answer with the reason): a
    UsernameError stops the account from being made."""
    if raw or instance.pk is not None:
        return
    instance.username = usernames.clean(instance.username)
    usernames.check_available(instance.username)


@receiver(post_save, sender=settings.AUTH_USER_MODEL)
def remember_username_key(sender, instance, created, raw=False, update_fields=None, **kwargs):
    """Store the key of the account's name, however the account was made or renamed
    (a restored backup brings its keys with it)."""
    if raw or (update_fields is not None and "username" not in update_fields):
        return
    usernames.remember(instance, created)
