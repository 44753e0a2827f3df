"""Comments on a review (issue 49, item 4): threads pinned to a frame, a cut or a segment,
read by the review's annotator and the project's reviewers and admins; another annotator
reads them only once the capture is adjudicated, an outsider never."""

from django.contrib.auth import get_user_model

from segmentation import services
from segmentation.models import Comment
from tests.segmentation.base import BaseTestCase


class CommentsTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.dora = get_user_model().objects.create_user("dora", password="dora-password")
        services.do_set_member(self.project, "dora", "annotator")
        self.capture = self.ready_capture(candidates=(100, 200), n_frames=400)
        self.base = f"/api/captures/{self.capture.pk}/"
        self.login(self.bob)
        self.review = self.client.post(self.base + "review/").json()
        self.url = f"{self.base}reviews/{self.review['id']}/comments/"

    def comment(self, **body):
        return self.client.post(self.url, body, format="json")

    def test_it_pins_a_thread_to_a_frame_and_threads_replies(self):
        first = self.comment(text="left foot slides here", frame=150).json()
        self.login(self.rachel)
        reply = self.comment(text="yes, cut before it", parent=first["id"]).json()
        self.assertEqual((reply["parent"], reply["frame"], reply["author"]), (first["id"], 150, "rachel"))
        self.login(self.bob)
        listed = self.client.get(self.base + "comments/").json()
        self.assertEqual([(c["text"], c["parent"]) for c in listed],
                         [("left foot slides here", None), ("yes, cut before it", first["id"])])

    def test_a_cut_thread_follows_its_cut_and_a_segment_thread_its_start(self):
        cut = self.review["cuts"][0]["id"]
        on_cut = self.comment(text="too early", cut=cut).json()
        on_segment = self.comment(text="is this a walk?", segment=1).json()
        self.assertEqual((on_cut["frame"], on_segment["frame"]), (100, 100))
        self.client.patch(f"{self.base}review/cuts/{cut}/", {"frame": 120, "version": 1}, format="json")
        frames = {c["text"]: c["frame"] for c in self.client.get(self.url).json()}
        self.assertEqual(frames, {"too early": 120, "is this a walk?": 120})

    def test_it_names_a_bad_anchor(self):
        for body, needle in (({"text": "x", "frame": 400}, "frame: must be between 0 and 399"),
                             ({"text": "x", "segment": 9}, "segment: the review has no segment 9"),
                             ({"text": "x", "cut": 999999}, "cut: 999999 is not a kept cut"),
                             ({"text": "x", "frame": 1, "segment": 0}, "exactly one of"),
                             ({"text": "   ", "frame": 1}, "text: "),
                             ({"text": "x", "parent": 999999}, "parent: comment 999999")):
            r = self.comment(**body)
            self.assertEqual(r.status_code, 400, body)
            self.assertIn(needle, r.json()["detail"])
        self.assertFalse(Comment.objects.exists())

    def test_another_annotator_gets_404_and_writes_nothing_before_adjudication(self):
        self.comment(text="private remark", frame=10)
        self.login(self.dora)
        self.assertEqual(self.client.get(self.url).status_code, 404)
        self.assertEqual(self.comment(text="sneaky", frame=5).status_code, 404)
        self.client.post(self.base + "review/")
        self.assertEqual(self.client.get(self.base + "comments/").json(), [])
        self.assertEqual(Comment.objects.count(), 1)

    def test_an_outsider_gets_404_everywhere(self):
        thread = self.comment(text="private remark", frame=10).json()
        self.login(self.charlie)
        self.assertEqual(self.client.get(self.url).status_code, 404)
        self.assertEqual(self.client.get(self.base + "comments/").status_code, 404)
        self.assertEqual(self.comment(text="x", frame=1).status_code, 404)
        self.assertEqual(self.client.patch(f"{self.url}{thread['id']}/", {"resolved": True},
                                           format="json").status_code, 404)
        self.assertNotIn("private", str(Comment.objects.filter(author=self.charlie).values()))

    def test_after_adjudication_other_annotators_read_but_do_not_write(self):
        self.comment(text="bob's remark", frame=10)
        self.client.post(self.base + "review/submit/", {"version": 1}, format="json")
        self.login(self.dora)
        self.client.post(self.base + "review/")
        self.login(self.rachel)
        r = self.client.put(self.base + "adjudication/", {"cuts": [100, 200], "labels": [None] * 3,
                                                          "version": 0}, format="json")
        self.assertEqual(r.status_code, 200, r.content)
        self.login(self.dora)
        self.assertEqual([c["text"] for c in self.client.get(self.base + "comments/").json()], ["bob's remark"])
        r = self.comment(text="me too", frame=3)
        self.assertEqual(r.status_code, 403)
        self.assertEqual(Comment.objects.count(), 1)

    def test_reviewers_and_the_annotator_resolve_a_thread_not_a_reply(self):
        thread = self.comment(text="check", frame=10).json()
        reply = self.comment(text="done", parent=thread["id"]).json()
        self.login(self.alice)
        r = self.client.patch(f"{self.url}{thread['id']}/", {"resolved": True}, format="json")
        self.assertEqual((r.status_code, r.json()["resolved"], r.json()["resolved_by"]), (200, True, "alice"))
        r = self.client.patch(f"{self.url}{reply['id']}/", {"resolved": True}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("is a reply", r.json()["detail"])

    def test_a_comment_does_not_move_the_reviews_version(self):
        self.login(self.rachel)
        self.comment(text="look here", frame=10)
        self.login(self.bob)
        r = self.client.post(self.base + "review/cuts/", {"frame": 300, "version": 1}, format="json")
        self.assertEqual(r.status_code, 201)
