"""A signed-in browser's cross-site POST with a ``text/plain`` body (what an HTML form can
send without a preflight) is answered with the CSRF 403 on every write route, never with
415 from parsing the body first (issue 48, item 12).

The routes are read from the URL conf, so a route added later is held to the same rule.
"""

import re
from types import SimpleNamespace

from django.test import Client
from django.urls import URLPattern, URLResolver, get_resolver
from rest_framework.authentication import SessionAuthentication

from tests.segmentation.base import BaseTestCase

WRITES = ("post", "put", "patch", "delete")
PARAM = re.compile(r"<(?:(\w+):)?(\w+)>")


def routes(patterns=None, prefix=""):
    """(path, view class) of every DRF route under ``/api/`` in the URL conf."""
    for entry in get_resolver().url_patterns if patterns is None else patterns:
        if isinstance(entry, URLResolver):
            yield from routes(entry.url_patterns, prefix + str(entry.pattern))
        elif isinstance(entry, URLPattern):
            view = getattr(entry.callback, "cls", None)
            if view is not None and (prefix + str(entry.pattern)).startswith(("api/", "^api/")):
                yield prefix + str(entry.pattern), entry.callback


def concrete(pattern):
    """A URL for ``pattern``: path parameters filled with 1 (ids) or ``x``."""
    url = re.sub(r"\(\?P<\w+>[^)]*\)", "1", pattern)  # router regexes: (?P<pk>[^/.]+)
    url = PARAM.sub(lambda m: "x" if m.group(1) in ("str", "slug") else "1", url)
    url = url.replace("^", "").replace("$", "").replace("\\.", ".")
    return "/" + url


def trusts_a_session(view_class, method):
    """Whether ``view_class`` signs a ``method`` request in by its session cookie (health
    and obtaining a token with a password do not, so a cross-site post gains nothing)."""
    view = view_class()
    view.request = SimpleNamespace(method=method.upper())
    return any(isinstance(a, SessionAuthentication) for a in view.get_authenticators())


def write_routes():
    """(method, url) of every write a route's view answers."""
    found = []
    for pattern, callback in routes():
        actions = getattr(callback, "actions", None)  # a viewset route: method -> action
        methods = actions.keys() if actions else [m for m in WRITES if hasattr(callback.cls, m)]
        found += [(m, concrete(pattern)) for m in methods
                  if m in WRITES and trusts_a_session(callback.cls, m)]
    return sorted(set(found))


class CsrfBeforeBodyTestCase(BaseTestCase):
    def setUp(self):
        self.browser = Client(enforce_csrf_checks=True)
        self.browser.raise_request_exception = False
        self.browser.force_login(self.alice)
        self.browser.get("/login/")  # the page sets the CSRF cookie, as a visit would

    def test_every_write_route_is_found(self):
        found = write_routes()
        self.assertGreaterEqual(len([m for m, _ in found if m == "post"]), 18, found)

    def test_a_text_plain_post_without_a_token_is_the_csrf_403(self):
        self.assertIn("csrftoken", self.browser.cookies)
        for method, url in write_routes():
            with self.subTest(method=method, url=url):
                r = getattr(self.browser, method)(url, "name=evil&x=1", content_type="text/plain",
                                                  HTTP_ORIGIN="http://testserver")
                self.assertEqual(r.status_code, 403, r.content[:300])
                self.assertIn("CSRF", r.json()["detail"])

    def test_a_cross_site_origin_is_the_csrf_403(self):
        for method, url in write_routes():
            with self.subTest(method=method, url=url):
                r = getattr(self.browser, method)(url, "{}", content_type="text/plain",
                                                  HTTP_ORIGIN="https://evil.example")
                self.assertEqual(r.status_code, 403, r.content[:300])
                self.assertIn("CSRF", r.json()["detail"])

    def test_a_post_with_the_token_still_reaches_the_view(self):
        token = self.browser.cookies["csrftoken"].value
        r = self.browser.post("/api/projects/", {"name": "Studio C"}, content_type="application/json",
                              HTTP_X_CSRFTOKEN=token)
        self.assertEqual(r.status_code, 201, r.content)
