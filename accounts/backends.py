from django.contrib.auth import get_user_model
from django.contrib.auth.backends import ModelBackend

from accounts.usernames import find_user


class UsernameBackend(ModelBackend):
    """Django's password check, finding the account by any spelling of its username
    (``usernames.key``): the sign-in throttle counts by that key, so what it locks is
    exactly what could sign in."""

    def authenticate(self, request, username=None, password=None, **kwargs):
        users = get_user_model()
        if username is None:
            username = kwargs.get(users.USERNAME_FIELD)
        if not isinstance(username, str) or password is None:
            return None
        user = find_user(username)
        if user is None:
            # Hash anyway, so the answer takes as long whether or not the account exists.
            users().set_password(password)
            return None
        if user.check_password(password) and self.user_can_authenticate(user):
            return user
        return None
