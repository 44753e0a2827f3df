"""When a review starts: reading never creates one, the first write starts it from the
latest finished run's candidates, and a review started before detection finished takes
the candidates in once they exist."""

from segmentation import services, tasks
from segmentation.models import DetectionRun, Review, ReviewEvent
from tests.segmentation.base import BaseTestCase, synthetic_bvh


class ReviewStartTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.bob)

    def url(self, capture):
        return f"/api/captures/{capture.pk}/review/"

    def test_it_creates_no_review_on_get(self):
        capture = self.ready_capture(candidates=(100, 200), n_frames=400)
        response = self.client.get(self.url(capture))
        assert response.status_code == 200, response.content
        body = response.json()
        assert not Review.objects.exists()
        assert (body["id"], body["status"], body["version"]) == (None, "not_started", 1)
        assert [c["frame"] for c in body["cuts"]] == [100, 200]
        assert [(s["start"], s["stop"]) for s in body["segments"]] == [(0, 100), (100, 200), (200, 400)]

    def test_it_creates_no_review_when_reading_its_log(self):
        capture = self.ready_capture()
        assert self.client.get(self.url(capture) + "events/").json() == []
        assert not Review.objects.exists()

    def test_it_starts_the_review_from_the_candidates_on_the_first_write(self):
        capture = self.ready_capture(candidates=(100, 200), n_frames=400)
        self.client.get(self.url(capture))
        response = self.client.post(self.url(capture) + "cuts/", {"frame": 150, "version": 1},
                                    format="json")
        assert response.status_code == 201, response.content
        review = response.json()
        assert [(c["frame"], c["origin"]) for c in review["cuts"]] == [
            (100, "candidate"), (150, "inserted"), (200, "candidate")]
        assert review["version"] == 2
        assert list(ReviewEvent.objects.values_list("action", flat=True)) == ["create", "insert"]

    def test_a_label_based_on_the_unstarted_review_lands_on_the_segment_seen(self):
        capture = self.ready_capture(candidates=(100, 200), n_frames=400)
        segments = self.client.get(self.url(capture)).json()["segments"]
        response = self.client.patch(self.url(capture) + "segments/1/", {"label": "walk", "version": 1},
                                     format="json")
        assert response.status_code == 200, response.content
        labelled = [(s["start"], s["stop"]) for s in response.json()["segments"] if s["label"] == "walk"]
        assert labelled == [(segments[1]["start"], segments[1]["stop"])]


class EarlyReviewTestCase(BaseTestCase):
    """Bob opens a capture whose project defaults are broken: it is ready, but no run
    has finished, so his review starts empty."""

    def setUp(self):
        super().setUp()
        self.project.default_method, self.project.default_params = "bone_angle", {"param": 9}
        self.project.save()
        self.login(self.alice)
        capture_id = self.upload(synthetic_bvh(seed=2, duration=20.0), name="early.bvh").json()["id"]
        self.capture = self.ingest(capture_id)
        assert self.capture.status == "ready" and self.capture.latest_finished_run() is None
        self.login(self.bob)
        self.url = f"/api/captures/{self.capture.pk}/review/"
        self.early = self.client.post(self.url).json()
        assert (self.early["run"], self.early["cuts"]) == (None, [])

    def test_an_early_review_takes_in_the_candidates_when_detection_finishes(self):
        self.client.post(self.url + "cuts/", {"frame": 500, "version": 1}, format="json")
        run = services.do_start_run(self.capture, self.alice, "bone_angle", {})
        tasks.detect(run.pk)
        run.refresh_from_db()
        assert run.status == "ready" and run.candidates
        review = self.client.get(self.url).json()
        assert review["run"] == run.pk
        candidates = {c["frame"] for c in run.candidates} - {500}
        assert {c["frame"] for c in review["cuts"] if c["origin"] == "candidate"} == candidates
        # What bob did before stays, and the change counts as a new version.
        assert [c["frame"] for c in review["cuts"] if c["origin"] == "inserted"] == [500]
        assert review["version"] == 3
        assert ReviewEvent.objects.filter(action="candidates").count() == 1

    def test_an_early_review_that_missed_the_hand_over_takes_them_in_with_its_next_write(self):
        # A run that finished without handing its candidates over (e.g. it committed
        # while the review was being created).
        run = DetectionRun.objects.create(capture=self.capture, method="bone_angle", status="ready",
                                          candidates=[{"frame": 300, "confidence": 0.9}])
        refused = self.client.post(self.url + "cuts/", {"frame": 600, "version": 1}, format="json")
        # The review changed under the write (its segment indexes moved): redo it.
        assert refused.status_code == 409, refused.content
        current = refused.json()["review"]
        assert (current["run"], [c["frame"] for c in current["cuts"]]) == (run.pk, [300])
        redo = self.client.post(self.url + "cuts/", {"frame": 600, "version": current["version"]},
                                format="json")
        assert [c["frame"] for c in redo.json()["cuts"]] == [300, 600]

    def test_a_submitted_review_takes_no_candidates(self):
        self.client.post(self.url + "submit/", {"version": 1}, format="json")
        run = services.do_start_run(self.capture, self.alice, "bone_angle", {})
        tasks.detect(run.pk)
        review = Review.objects.get(annotator=self.bob)
        assert (review.run_id, review.cuts.count(), review.version) == (None, 0, 2)
