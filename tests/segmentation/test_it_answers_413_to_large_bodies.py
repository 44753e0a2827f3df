"""A JSON body over DATA_UPLOAD_MAX_MEMORY_SIZE (10 MB) is answered 413 with a message,
not 500, on every write endpoint, the unauthenticated token endpoint included (issue 48,
item 9)."""

import json

from django.conf import settings
from rest_framework.test import APIClient

from tests.segmentation.base import BaseTestCase


def huge_body(**fields):
    """JSON just over the limit: ``fields`` and a long ``note``."""
    return json.dumps({**fields, "note": "x" * (settings.DATA_UPLOAD_MAX_MEMORY_SIZE + 1)})


class LargeBodyTestCase(BaseTestCase):
    def send(self, method, url, body, client=None):
        client = client or self.client
        client.raise_request_exception = False
        return getattr(client, method)(url, body, content_type="application/json")

    def assert_413(self, response):
        self.assertEqual(response.status_code, 413, response.content[:300])
        self.assertIn("request body is larger than 10485760 bytes", response.json()["detail"])

    def test_the_token_endpoint_answers_413_without_credentials(self):
        self.assert_413(self.send("post", "/api/auth/token/",
                                  huge_body(username="bob", password="bob-password"),
                                  client=APIClient()))

    def test_write_endpoints_answer_413(self):
        self.login(self.alice)
        capture = self.ready_capture()
        review = f"/api/captures/{capture.pk}/review/"
        self.client.post(review)  # started (its POST reads no body)
        for method, url in (("post", "/api/projects/"),
                            ("patch", f"/api/projects/{self.project.pk}/"),
                            ("post", review + "cuts/"),
                            ("patch", review + "segments/0/"),
                            ("post", review + "submit/")):
            with self.subTest(url=url):
                self.assert_413(self.send(method, url, huge_body(name="x", frame=5, version=1)))

    def test_a_body_under_the_limit_is_read_as_before(self):
        self.login(self.alice)
        r = self.send("post", "/api/projects/", json.dumps({"name": "Studio B"}))
        self.assertEqual(r.status_code, 201, r.content)
