"""Every free-text field is bounded, and the refusal says the bound (issue 33, item 4): a
100,000-character label name or a 5 MB return comment is neither stored nor echoed."""

import pytest
import yaml

from segmentation import services
from segmentation.errors import Invalid
from segmentation.models import Label, Review
from segmentation.services.returns import do_return_review
from segmentation.services.taxonomy import do_change_label
from tests.segmentation.test_api_schema import export_schema
from tests.segmentation.test_library import LibraryTestCase, submit_review

# Signing in for a token is DRF's own AuthTokenSerializer (the accounts app's).
UNBOUNDED_ALLOWED = {"AuthTokenRequest.username", "AuthTokenRequest.password"}


class TextBoundsTest(LibraryTestCase):
    def test_it_refuses_a_100000_character_label_name_saying_the_bound(self):
        self.login(self.alice)
        url = f"/api/projects/{self.project.pk}/labels/"
        for r in (self.client.post(url, {"name": "x" * 100_000}, format="json"),
                  self.client.patch(f"{url}{self.walk.pk}/", {"name": "x" * 100_000}, format="json")):
            assert r.status_code == 400
            assert r.json()["detail"] == "name: must be at most 100 characters, got 100000"
        assert sorted(Label.objects.filter(project=self.project).values_list("name", flat=True)) == [
            "punch", "walk"]

    def test_it_refuses_a_5_mb_return_comment_saying_the_bound(self):
        capture = self.ready_capture()
        review = submit_review(capture, self.bob, [100], ["walk", "punch"])
        self.login(self.rachel)
        r = self.client.post(f"/api/captures/{capture.pk}/reviews/{review.pk}/return/",
                             {"comment": "x" * 5_000_000}, format="json")
        assert r.status_code == 400
        assert r.json()["detail"] == "comment: must be at most 2000 characters, got 5000000"
        review.refresh_from_db()
        assert (review.status, review.return_comment) == ("submitted", "")

    def test_the_services_hold_every_other_caller_to_the_same_bounds(self):
        capture = self.ready_capture()
        review = submit_review(capture, self.bob, [100], ["walk", "punch"])
        for call, message in [
            (lambda: do_change_label(self.walk, name="x" * 101),
             "name: must be at most 100 characters, got 101"),
            (lambda: services.do_add_label(self.project, "x" * 101),
             "name: must be at most 100 characters, got 101"),
            (lambda: do_return_review(review, self.rachel, "x" * 2001),
             "comment: must be at most 2000 characters, got 2001"),
            (lambda: services.do_create_project(self.alice, "x" * 201),
             "name: must be at most 200 characters, got 201"),
        ]:
            with pytest.raises(Invalid) as caught:
                call()
            assert str(caught.value) == message
        assert Review.objects.get(pk=review.pk).status == "submitted"


def test_every_string_a_request_body_takes_has_a_maximum_length(tmp_path):
    path = tmp_path / "openapi.yml"
    result = export_schema(path)
    assert result.returncode == 0, result.stderr
    schema = yaml.safe_load(path.read_text())
    components = schema["components"]["schemas"]
    bodies = {media["schema"]["$ref"].rsplit("/", 1)[1]
              for operations in schema["paths"].values() for operation in operations.values()
              if isinstance(operation, dict) and "requestBody" in operation
              for media in operation["requestBody"]["content"].values() if "$ref" in media["schema"]}
    unbounded = set()

    def walk(node, where, seen):
        if "$ref" in node:
            name = node["$ref"].rsplit("/", 1)[1]
            if name not in seen:
                walk(components[name], name, seen | {name})
            return
        if node.get("type") == "string" and not {"maxLength", "enum", "format"} & set(node):
            unbounded.add(where)
        for key, child in node.get("properties", {}).items():
            walk(child, f"{where}.{key}", seen)
        if "items" in node:
            walk(node["items"], f"{where}[]", seen)
        for child in node.get("allOf", []) + node.get("oneOf", []) + node.get("anyOf", []):
            walk(child, where, seen)

    for name in bodies:
        walk({"$ref": f"#/components/schemas/{name}"}, name, frozenset())
    assert bodies and unbounded - UNBOUNDED_ALLOWED == set()
