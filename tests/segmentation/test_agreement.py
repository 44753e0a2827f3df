"""Agreement between annotators, adjudication into a gold version, and the project
dashboard, through the API.

The two reviews of ``LibraryTestCase.two_reviews`` on a 400-frame take at 120 fps
(tolerance 0.25 s = 30 frames), worked out by hand:

    bob : cuts 100, 200, 300   labels walk | punch | walk | punch
    dana: cuts 110, 250        labels walk | punch | punch

- boundaries: only 100~110 match; bob's precision 1/3, recall 1/2, F1 = 2*1/5 = 0.4.
- frames alike: [0,100) + [110,200) + [300,400) = 290 of 400, p_o = 0.725; bob has
  200 walk / 200 punch frames, dana 110 / 290, p_e = (200*110 + 200*290) / 400^2 = 0.5,
  kappa = (0.725 - 0.5) / 0.5 = 0.45.
- overlap: walk 100 / 210, punch 190 / 300.
"""

import pytest

from segmentation.models import Adjudication, LibrarySegment, ReviewEvent
from tests.segmentation.test_library import LibraryTestCase, submit_review


class AgreementApiTest(LibraryTestCase):
    def agreement(self, capture, query=""):
        return self.client.get(f"/api/captures/{capture.pk}/agreement/{query}")

    def test_it_reports_the_hand_worked_pair(self):
        capture, bob, dana = self.two_reviews()
        self.login(self.rachel)
        body = self.agreement(capture).json()
        assert body["n_reviews"] == 2 and body["tolerance_s"] == 0.25
        (pair,) = body["pairs"]
        assert pair["a"] == {"review": bob.pk, "annotator": "bob"}
        assert (pair["precision"], pair["recall"], pair["f1"], pair["matched"]) == (
            pytest.approx(1 / 3, abs=1e-4), 0.5, 0.4, 1)
        assert pair["kappa"] == pytest.approx(0.45)
        assert body["labels"] == {"method": "cohen_kappa", "value": pytest.approx(0.45)}
        assert body["per_label"] == [
            {"label": "punch", "overlap": pytest.approx(190 / 300, abs=1e-4), "frames": 300},
            {"label": "walk", "overlap": pytest.approx(100 / 210, abs=1e-4), "frames": 110 + 100},
        ]

    def test_it_widens_the_tolerance_on_request(self):
        capture, _, _ = self.two_reviews()
        self.login(self.rachel)
        # 0.5 s = 60 frames: 200~250 now matches too (300 is then left over).
        (pair,) = self.agreement(capture, "?tolerance=0.5").json()["pairs"]
        assert pair["matched"] == 2 and pair["f1"] == 0.8

    def test_it_uses_krippendorffs_alpha_for_three_annotators(self):
        capture, _, _ = self.two_reviews()
        submit_review(capture, self.alice, [100, 200, 300], ["walk", "punch", "walk", "punch"])
        self.login(self.alice)
        body = self.agreement(capture).json()
        assert body["n_reviews"] == 3 and len(body["pairs"]) == 3
        assert body["labels"]["method"] == "krippendorff_alpha"
        assert body["labels"]["value"] == body["alpha"]
        assert 0.45 < body["alpha"] < 1

    def test_it_reports_nothing_to_compare_for_one_review(self):
        capture = self.ready_capture()
        submit_review(capture, self.bob, [100], ["walk", "punch"])
        self.login(self.rachel)
        body = self.agreement(capture).json()
        assert body["n_reviews"] == 1 and body["pairs"] == [] and body["boundary_f1"] is None

    def test_it_hides_agreement_from_outsiders(self):
        capture, _, _ = self.two_reviews()
        self.login(self.charlie)
        assert self.agreement(capture).status_code == 404

    def test_it_tells_an_annotator_agreement_is_for_reviewers(self):
        capture, _, _ = self.two_reviews()
        self.login(self.bob)
        response = self.agreement(capture)
        assert response.status_code == 403
        assert "reviewers and admins" in response.json()["detail"]

    def test_it_rejects_a_bad_tolerance_naming_it(self):
        capture, _, _ = self.two_reviews()
        self.login(self.rachel)
        response = self.agreement(capture, "?tolerance=-1")
        assert response.status_code == 400
        assert response.json()["detail"] == "tolerance: must be between 0 and 10, got -1"


class AdjudicationApiTest(LibraryTestCase):
    def setUp(self):
        super().setUp()
        self.capture, self.bob_review, _ = self.two_reviews()
        self.url = f"/api/captures/{self.capture.pk}/adjudication/"

    def save(self, cuts, labels, version=0, **extra):
        return self.client.put(self.url, {"cuts": cuts, "labels": labels, "version": version,
                                          **extra}, format="json")

    def test_it_overlays_every_annotators_cuts_and_labels(self):
        self.login(self.rachel)
        body = self.client.get(self.url).json()
        assert [(r["annotator"]["username"], r["cuts"]) for r in body["reviews"]] == [
            ("bob", [100, 200, 300]), ("dana", [110, 250])]
        assert body["reviews"][1]["segments"][1] == {"start": 110, "stop": 250, "label": "punch"}
        assert body["gold"] is None
        assert body["agreement"]["boundary_f1"] == 0.4

    def test_it_makes_a_gold_version_that_the_library_prefers(self):
        self.login(self.rachel)
        response = self.save([100, 250], ["walk", "punch", "punch"], source_review=self.bob_review.pk)
        assert response.status_code == 200, response.content
        gold = response.json()["gold"]
        assert gold["version"] == 1 and gold["adjudicator"] == "rachel"
        assert gold["source_review"] == self.bob_review.pk
        listed = self.client.get("/api/segments/").json()["results"]
        assert {(r["start"], r["stop"], r["label"], r["gold"]) for r in listed} == {
            (0, 100, "walk", True), (100, 250, "punch", True), (250, 400, "punch", True)}
        # Gold [100, 250) punch: bob agrees on [100, 200) and dana on [110, 250), 240 of 300.
        assert next(r for r in listed if r["start"] == 100)["agreement"] == pytest.approx(0.8)
        # The annotators' versions are still there on request.
        assert self.client.get("/api/segments/?gold=false").json()["count"] == 7

    def test_it_shows_gold_segments_to_annotators(self):
        self.login(self.rachel)
        self.save([100, 250], ["walk", "punch", "punch"])
        self.login(self.dana)
        listed = self.client.get("/api/segments/").json()["results"]
        assert {r["gold"] for r in listed} == {True}
        assert self.client.get("/api/segments/?gold=false").json()["count"] == 3

    def test_it_refuses_a_save_based_on_a_stale_gold_version(self):
        self.login(self.rachel)
        assert self.save([100], ["walk", "punch"]).status_code == 200
        response = self.save([200], ["walk", "punch"], version=0)
        assert response.status_code == 409
        assert response.json()["gold"]["cuts"] == [100]
        assert self.save([200], ["walk", "punch"], version=1).json()["gold"]["version"] == 2
        assert Adjudication.objects.get().cuts == [200]

    def test_it_rejects_bad_gold_versions_naming_the_fault(self):
        self.login(self.rachel)
        for cuts, labels, message in [
            ([250, 100], ["walk", "walk", "walk"], "cuts: cut 1 at frame 100 is not after the previous cut (250)"),
            ([0], ["walk", "walk"], "cuts: cut 0 at frame 0 is outside 1..399"),
            ([100], ["walk"], "labels: expected 2 labels (one per segment), got 1"),
            ([100], ["walk", "dance"], "labels: segment 1 has label 'dance', which is not a label"),
        ]:
            response = self.save(cuts, labels)
            assert response.status_code == 400, cuts
            assert message in response.json()["detail"]
        assert not Adjudication.objects.exists()

    def test_it_refuses_adjudication_to_annotators(self):
        self.login(self.bob)
        assert self.client.get(self.url).status_code == 403
        assert self.save([100], ["walk", "punch"]).status_code == 403
        assert not LibrarySegment.objects.filter(is_gold=True).exists()


class DashboardApiTest(LibraryTestCase):
    def test_it_counts_captures_by_state_and_annotator_edits_from_the_audit_log(self):
        self.ready_capture(name="untouched.bvh")
        started = self.ready_capture(name="started.bvh")
        self.client.force_authenticate(self.bob)
        self.client.post(f"/api/captures/{started.pk}/review/")
        disputed, _, _ = self.two_reviews(self.ready_capture(name="disputed.bvh"))
        agreed = self.ready_capture(name="agreed.bvh")
        for user in (self.bob, self.dana):
            submit_review(agreed, user, [100, 200], ["walk", "punch", "walk"])
        gold, _, _ = self.two_reviews(self.ready_capture(name="gold.bvh"))
        self.login(self.rachel)
        self.client.put(f"/api/captures/{gold.pk}/adjudication/",
                        {"cuts": [100], "labels": ["walk", "punch"], "version": 0}, format="json")

        body = self.client.get(f"/api/projects/{self.project.pk}/dashboard/").json()
        states = {c["name"]: c["state"] for c in body["captures"]}
        assert states == {"untouched.bvh": "unreviewed", "started.bvh": "in_review",
                          "disputed.bvh": "in_review", "agreed.bvh": "agreed",
                          "gold.bvh": "adjudicated"}
        assert body["states"] == {"unreviewed": 1, "in_review": 2, "agreed": 1, "adjudicated": 1}
        bob = next(a for a in body["annotators"] if a["username"] == "bob")
        logged = ReviewEvent.objects.filter(review__annotator=self.bob).exclude(
            action__in=["create", "submit"])
        assert bob["edits_total"] == logged.count() > 0
        assert bob["edits"]["delete"] == logged.filter(action="delete").count()
        assert bob["submitted"] == 3 and bob["in_progress"] == 1
        labels = {entry["label"]: entry for entry in body["labels"]}
        assert labels["walk"]["captures"] == 3 and 0 < labels["walk"]["overlap"] <= 1
        assert body["library"]["gold"] == 2
        # The dashboard's stored summary says what the agreement endpoint says.
        row = next(c for c in body["captures"] if c["name"] == "disputed.bvh")
        live = self.client.get(f"/api/captures/{disputed.pk}/agreement/").json()
        assert (row["boundary_f1"], row["label_agreement"]) == (live["boundary_f1"], live["labels"]["value"])

    def test_it_hides_the_dashboard_from_outsiders(self):
        self.login(self.charlie)
        assert self.client.get(f"/api/projects/{self.project.pk}/dashboard/").status_code == 404

    def test_it_tells_an_annotator_the_dashboard_is_for_reviewers(self):
        self.login(self.bob)
        response = self.client.get(f"/api/projects/{self.project.pk}/dashboard/")
        assert response.status_code == 403 and "reviewers and admins" in response.json()["detail"]
