from segmentation.models import ReviewEvent
from tests.segmentation.base import BaseTestCase


class ReviewTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture(candidates=(100, 200, 300), n_frames=400)
        self.url = f"/api/captures/{self.capture.pk}/review/"
        self.login(self.bob)

    def start(self):
        return self.client.post(self.url).json()

    def cut_at(self, review, frame):
        return next(c for c in review["cuts"] if c["frame"] == frame)

    def test_it_starts_from_the_latest_finished_runs_candidates(self):
        review = self.start()
        self.assertEqual(review["annotator"], {"id": self.bob.pk, "username": "bob"})
        self.assertEqual(review["status"], "in_progress")
        self.assertEqual(review["version"], 1)
        self.assertEqual([c["frame"] for c in review["cuts"]], [100, 200, 300])
        self.assertEqual({c["fate"] for c in review["cuts"]}, {"pending"})
        self.assertEqual({c["origin"] for c in review["cuts"]}, {"candidate"})
        self.assertEqual(review["cuts"][1]["candidate_frame"], 200)
        self.assertAlmostEqual(review["cuts"][1]["confidence"], 0.6)

    def test_it_creates_the_review_once(self):
        first = self.client.post(self.url).json()
        second = self.client.post(self.url).json()
        self.assertEqual(first["id"], second["id"])
        self.assertEqual(ReviewEvent.objects.filter(action="create").count(), 1)

    def test_it_reports_segments_between_kept_cuts(self):
        segments = self.start()["segments"]
        self.assertEqual(
            [(s["index"], s["start"], s["stop"]) for s in segments],
            [(0, 0, 100), (1, 100, 200), (2, 200, 300), (3, 300, 400)],
        )

    def test_it_inserts_a_cut(self):
        self.start()
        r = self.client.post(self.url + "cuts/", {"frame": 150, "version": 1}, format="json")
        self.assertEqual(r.status_code, 201)
        review = r.json()
        self.assertEqual(review["version"], 2)
        inserted = self.cut_at(review, 150)
        self.assertEqual((inserted["origin"], inserted["fate"]), ("inserted", "accepted"))
        self.assertIsNone(inserted["candidate_frame"])
        self.assertEqual(len(review["segments"]), 5)

    def test_it_moves_a_cut_and_keeps_its_candidate_frame(self):
        cut = self.cut_at(self.start(), 200)
        r = self.client.patch(f"{self.url}cuts/{cut['id']}/", {"frame": 210, "version": 1}, format="json")
        self.assertEqual(r.status_code, 200)
        moved = self.cut_at(r.json(), 210)
        self.assertEqual((moved["fate"], moved["candidate_frame"]), ("moved", 200))

    def test_it_deletes_a_cut_and_merges_its_segments(self):
        cut = self.cut_at(self.start(), 200)
        r = self.client.patch(f"{self.url}cuts/{cut['id']}/", {"fate": "deleted", "version": 1}, format="json")
        review = r.json()
        self.assertEqual(self.cut_at(review, 200)["fate"], "deleted")
        self.assertEqual([(s["start"], s["stop"]) for s in review["segments"]],
                         [(0, 100), (100, 300), (300, 400)])

    def test_it_accepts_and_resets_a_cut(self):
        cut = self.cut_at(self.start(), 100)
        r = self.client.patch(f"{self.url}cuts/{cut['id']}/", {"fate": "accepted", "version": 1}, format="json")
        self.assertEqual(self.cut_at(r.json(), 100)["fate"], "accepted")
        r = self.client.patch(f"{self.url}cuts/{cut['id']}/", {"fate": "pending", "version": 2}, format="json")
        self.assertEqual(self.cut_at(r.json(), 100)["fate"], "pending")

    def test_it_labels_a_segment_and_the_label_follows_its_cut(self):
        review = self.start()
        r = self.client.patch(self.url + "segments/2/", {"label": "walk", "version": 1}, format="json")
        self.assertEqual(r.json()["segments"][2]["label"], "walk")
        cut = self.cut_at(review, 200)
        r = self.client.patch(f"{self.url}cuts/{cut['id']}/", {"frame": 250, "version": 2}, format="json")
        segment = r.json()["segments"][2]
        self.assertEqual((segment["start"], segment["label"]), (250, "walk"))

    def test_it_clears_a_label(self):
        self.start()
        self.client.patch(self.url + "segments/0/", {"label": "punch", "version": 1}, format="json")
        r = self.client.patch(self.url + "segments/0/", {"label": None, "version": 2}, format="json")
        self.assertIsNone(r.json()["segments"][0]["label"])

    def test_it_submits(self):
        self.start()
        r = self.client.post(self.url + "submit/", {"version": 1}, format="json")
        self.assertEqual(r.status_code, 200)
        self.assertEqual(r.json()["status"], "submitted")

    def test_it_refuses_edits_after_submission(self):
        self.start()
        self.client.post(self.url + "submit/", {"version": 1}, format="json")
        r = self.client.post(self.url + "cuts/", {"frame": 150, "version": 2}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("submitted", r.json()["detail"])

    def test_it_logs_every_action(self):
        cut = self.cut_at(self.start(), 100)
        self.client.post(self.url + "cuts/", {"frame": 150, "version": 1}, format="json")
        self.client.patch(f"{self.url}cuts/{cut['id']}/", {"frame": 90, "version": 2}, format="json")
        self.client.patch(self.url + "segments/1/", {"label": "walk", "version": 3}, format="json")
        self.client.post(self.url + "submit/", {"version": 4}, format="json")
        events = self.client.get(self.url + "events/").json()
        self.assertEqual([e["action"] for e in events], ["create", "insert", "move", "label", "submit"])
        self.assertEqual({e["user"] for e in events}, {"bob"})
        move = events[2]
        self.assertEqual((move["cut"], move["before"]["frame"], move["after"]["frame"]), (cut["id"], 100, 90))

    def test_it_refuses_a_review_of_a_capture_that_is_not_ready(self):
        self.capture.status = "processing"
        self.capture.save()
        r = self.client.get(self.url)
        self.assertEqual(r.status_code, 400)
        self.assertIn("processing", r.json()["detail"])

    def test_without_a_finished_run_it_starts_empty_for_manual_cutting(self):
        self.capture.runs.update(status="failed", error="boom")
        review = self.start()
        self.assertEqual((review["run"], review["cuts"]), (None, []))
        self.assertEqual([(s["start"], s["stop"]) for s in review["segments"]], [(0, 400)])
