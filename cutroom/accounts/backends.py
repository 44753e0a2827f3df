"""The sign-in backend under the path it had while the accounts app lived in the project
package.

A session stores the dotted path of the backend that signed it in, and Django keeps the
session only while that path is in ``AUTHENTICATION_BACKENDS``: without this name, every
session made before the move would end at once. It finds the user of such a session and
signs no one in itself (``accounts.backends.UsernameBackend`` does).
"""

from accounts.backends import UsernameBackend as CurrentBackend


class UsernameBackend(CurrentBackend):
    def authenticate(self, request, username=None, password=None, **kwargs):
        return None
