"""Bodies and paths built to break the service get a 400 naming the field, never a 500
(issue 33, item 2): integers beyond 64 bits in path ids, in lists and in method
parameters, non-finite numbers, and JSON nested deep enough to exhaust the decoder."""

from segmentation.api.common.parsers import MAX_DEPTH
from segmentation.models import Review
from tests.segmentation.test_library import LibraryTestCase, submit_review

BIG = 2**64 + 7
HUGE = int("9" * 400)


def nested(levels):
    """JSON text of ``levels`` arrays, one inside the other."""
    return "[" * levels + "]" * levels


class HostileBodyTest(LibraryTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture()
        self.review = submit_review(self.capture, self.bob, [100], ["walk", "punch"])
        self.alice.is_superuser = True  # site admins create accounts
        self.alice.save()
        self.login(self.alice)
        p, c = self.project.pk, self.capture.pk
        self.endpoints = {
            "assignments": ("post", f"/api/projects/{p}/assignments/", "captures"),
            "members": ("post", f"/api/projects/{p}/members/", "username"),
            "new-account": ("post", f"/api/projects/{p}/members/new-account/", "username"),
            "labels": ("post", f"/api/projects/{p}/labels/", "name"),
            "label": ("patch", f"/api/projects/{p}/labels/{self.walk.pk}/", "name"),
            "label order": ("post", f"/api/projects/{p}/labels/order/", "order"),
            "adjudication": ("put", f"/api/captures/{c}/adjudication/", "cuts"),
            "return": ("post", f"/api/captures/{c}/reviews/{self.review.pk}/return/", "comment"),
            "project": ("patch", f"/api/projects/{p}/", "default_params"),
            "run": ("post", f"/api/captures/{c}/runs/", "params"),
        }

    def send(self, endpoint, text):
        method, url, _ = self.endpoints[endpoint]
        return self.client.generic(method.upper(), url, text, content_type="application/json")

    def test_it_refuses_a_deeply_nested_body_on_every_endpoint_naming_the_field(self):
        for endpoint, (_, _, field) in self.endpoints.items():
            r = self.send(endpoint, f'{{"{field}": {nested(100_000)}}}')
            assert r.status_code == 400, (endpoint, r.content[:200])
            assert r.json()["detail"].startswith(
                f"{field}: nested deeper than {MAX_DEPTH} levels"), (endpoint, r.json())

    def test_it_refuses_a_deeply_nested_bare_array(self):
        r = self.send("labels", nested(100_000))
        assert r.status_code == 400
        assert r.json()["detail"].startswith(f"body: nested deeper than {MAX_DEPTH} levels")

    def test_it_reads_a_body_nested_as_deep_as_allowed(self):
        r = self.send("label order", f'{{"order": {nested(MAX_DEPTH - 1)}}}')
        assert r.status_code == 400  # a list of lists is not an order, but it is read
        assert r.json()["detail"].startswith("order: ")
        assert "nested deeper" not in r.json()["detail"]

    def test_it_refuses_an_id_beyond_64_bits_in_a_list(self):
        r = self.client.post(self.endpoints["assignments"][1],
                             {"captures": [self.capture.pk, BIG], "annotators": ["bob"]}, format="json")
        assert r.status_code == 400
        assert r.json()["detail"] == (f"captures: [1] = {BIG} is outside the integer range "
                                      f"{-2**63}..{2**63 - 1}")
        assert r.json()["captures"]

    def test_it_refuses_a_400_digit_integer_in_method_parameters(self):
        for endpoint, body in [("project", {"default_params": {"bandwidth": HUGE}}),
                               ("run", {"method": "bone_angle", "params": {"param": HUGE}})]:
            _, url, field = self.endpoints[endpoint]
            r = getattr(self.client, self.endpoints[endpoint][0])(url, body, format="json")
            assert r.status_code == 400, (endpoint, r.content[:300])
            assert r.json()["detail"].startswith(f"{field}: ") and "(400 digits)" in r.json()["detail"]

    def test_it_refuses_a_number_too_large_for_a_float(self):
        r = self.send("run", '{"method": "bone_angle", "params": {"param": 1e400}}')
        assert r.status_code == 400
        assert r.json()["detail"] == "params: param = must be a finite number, got inf"

    def test_it_refuses_nan_which_json_does_not_have(self):
        r = self.send("run", '{"method": "bone_angle", "params": {"param": NaN}}')
        assert r.status_code == 400
        assert "NaN is not a number JSON allows" in r.json()["detail"]

    def test_it_refuses_huge_integers_in_gold_cuts_and_label_order(self):
        for endpoint, body, field in [
            ("adjudication", {"cuts": [BIG], "labels": ["walk", None], "version": 0}, "cuts"),
            ("label order", {"order": [self.walk.pk, -BIG]}, "order"),
        ]:
            method, url, _ = self.endpoints[endpoint]
            r = getattr(self.client, method)(url, body, format="json")
            assert r.status_code == 400, endpoint
            assert r.json()["detail"].startswith(f"{field}: ["), r.json()


class HostilePathTest(LibraryTestCase):
    def test_it_refuses_an_id_beyond_64_bits_in_any_path_naming_the_parameter(self):
        capture = self.ready_capture()
        review = submit_review(capture, self.bob, [100], ["walk", "punch"])
        self.login(self.alice)
        p, c = self.project.pk, capture.pk
        for method, url, name in [
            ("get", f"/api/captures/{BIG}/", "pk"),
            ("get", f"/api/projects/{BIG}/dashboard/", "pk"),
            ("post", f"/api/captures/{c}/reviews/{BIG}/return/", "review_id"),
            ("patch", f"/api/projects/{p}/members/{BIG}/", "user_id"),
            ("patch", f"/api/projects/{p}/labels/{BIG}/", "label_id"),
            ("patch", f"/api/captures/{c}/review/cuts/{BIG}/", "cut_id"),
            ("get", f"/api/segments/{HUGE}/", "pk"),
            ("post", f"/api/invitations/{BIG}/accept/", "pk"),
            ("delete", f"/api/projects/{p}/assignments/{BIG}/", "assignment_id"),
        ]:
            r = getattr(self.client, method)(url, {}, format="json")
            assert r.status_code == 400, (url, r.status_code)
            assert r.json()["detail"].startswith(f"{name}: "), r.json()
            assert "is not an id" in r.json()["detail"]
        assert Review.objects.get(pk=review.pk).status == "submitted"

    def test_it_still_answers_404_for_an_id_in_range_that_does_not_exist(self):
        self.login(self.alice)
        assert self.client.get(f"/api/captures/{2**63 - 1}/").status_code == 404
