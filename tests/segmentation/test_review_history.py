"""A review's history from its audit log: restore to any listed event, undo and redo that
survive a reload (each request is a fresh client), and who may restore whose review."""

from segmentation.models import ReviewEvent
from tests.segmentation.base import BaseTestCase


def shape(review):
    """What a restore must bring back exactly: every cut's frame and fate, every label. An
    inserted cut that did not exist yet comes back deleted (its id stays, for redo)."""
    gone = {c["id"] for c in review["cuts"] if c["origin"] == "inserted" and c["fate"] == "deleted"}
    return ({c["id"]: (c["frame"], c["fate"]) for c in review["cuts"] if c["id"] not in gone},
            [(s["start"], s["stop"], s["label"]) for s in review["segments"]])


class ReviewHistoryBase(BaseTestCase):
    """Bob's review of a 400-frame take after four edits, with the state after each."""

    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture(candidates=(100, 200, 300), n_frames=400)
        self.url = f"/api/captures/{self.capture.pk}/review/"
        self.login(self.bob)
        self.review = self.client.post(self.url).json()
        self.ids = [c["id"] for c in self.review["cuts"]]
        self.states = [shape(self.review)]
        # Four edits, each state kept: move, delete, insert, label.
        self.edit("patch", f"cuts/{self.ids[0]}/", frame=120)
        self.edit("patch", f"cuts/{self.ids[1]}/", fate="deleted")
        self.edit("post", "cuts/", frame=250)
        self.edit("patch", "segments/1/", label="walk")

    def edit(self, method, path, **data):
        data["version"] = self.review["version"]
        r = getattr(self.client, method)(self.url + path, data, format="json")
        assert r.status_code in (200, 201), r.content
        self.review = r.json()
        self.states.append(shape(self.review))
        return r

    def events(self, review_id=None):
        url = f"/api/captures/{self.capture.pk}/reviews/{review_id or self.review['id']}/events/"
        return self.client.get(url).json()

    def restore(self, event, version=None, review_id=None):
        url = f"/api/captures/{self.capture.pk}/reviews/{review_id or self.review['id']}/restore/"
        return self.client.post(url, {"event": event, "version": version or self.review["version"]}, format="json")

    def step(self, verb):
        r = self.client.post(self.url + f"{verb}/", {"version": self.review["version"]}, format="json")
        assert r.status_code == 200, r.content
        self.review = r.json()
        return self.review


class ReviewHistoryTestCase(ReviewHistoryBase):
    def test_it_restores_the_review_as_it_was_after_any_listed_event(self):
        events = self.events()
        assert [e["action"] for e in events] == ["create", "move", "delete", "insert", "label"]
        for index in (4, 1, 3, 0, 2):
            r = self.restore(events[index]["id"])
            assert r.status_code == 200, r.content
            self.review = r.json()
            assert shape(self.review) == self.states[index], index

    def test_a_restore_is_one_event_listing_what_it_changed(self):
        created = self.events()[0]["id"]
        self.review = self.restore(created).json()
        last = self.events()[-1]
        assert (last["action"], last["user"], last["after"]["event"], last["after"]["intent"]) == ("restore", "bob", created, None)
        inserted = max(self.states[3][0])
        assert sorted(last["after"]["cuts"]) == [[self.ids[0], 100, "pending"], [self.ids[1], 200, "pending"], [inserted, 250, "deleted"]]
        assert sorted(last["before"]["cuts"]) == [[self.ids[0], 120, "moved"], [self.ids[1], 200, "deleted"], [inserted, 250, "accepted"]]
        # A restore can itself be taken back: restoring the point before it.
        self.review = self.restore(self.events()[-2]["id"]).json()
        assert shape(self.review) == self.states[4]

    def test_undo_and_redo_walk_the_log_across_requests(self):
        # Every request here is a fresh one: the history is the server's, not a page's.
        for expected in (3, 2, 1, 0):
            assert shape(self.step("undo")) == self.states[expected]
        r = self.client.post(self.url + "undo/", {"version": self.review["version"]}, format="json")
        assert (r.status_code, r.json()["detail"]) == (400, f"undo: review {self.review['id']} has nothing to undo")
        for expected in (1, 2):
            assert shape(self.step("redo")) == self.states[expected]
        assert [e["after"]["intent"] for e in self.events()[5:]] == ["undo"] * 4 + ["redo"] * 2

    def test_a_new_edit_after_an_undo_clears_redo_and_undo_takes_back_a_restore(self):
        self.step("undo")
        self.edit("patch", f"cuts/{self.ids[2]}/", fate="accepted")
        r = self.client.post(self.url + "redo/", {"version": self.review["version"]}, format="json")
        assert r.status_code == 400 and "nothing to redo" in r.json()["detail"]
        before_restore = shape(self.review)
        self.review = self.restore(self.events()[0]["id"]).json()
        assert shape(self.step("undo")) == before_restore

    def test_it_refuses_a_stale_version_with_409_and_the_current_review(self):
        r = self.restore(self.events()[0]["id"], version=self.review["version"] - 1)
        assert r.status_code == 409
        assert r.json()["review"]["version"] == self.review["version"]
        r = self.client.post(self.url + "undo/", {"version": 1}, format="json")
        assert r.status_code == 409
        assert shape(self.client.get(self.url).json()) == self.states[-1]

    def test_it_refuses_an_event_of_another_review(self):
        self.login(self.rachel)
        self.client.post(self.url)
        theirs = ReviewEvent.objects.filter(review__annotator=self.rachel).first()
        self.login(self.bob)
        r = self.restore(theirs.pk)
        assert (r.status_code, r.json()["detail"]) == (400, f"event: review {self.review['id']} has no event {theirs.pk}")

    def test_a_submitted_review_is_not_restored(self):
        self.edit("post", "submit/")
        r = self.restore(self.events()[0]["id"])
        assert r.status_code == 400 and "submitted" in r.json()["detail"]

    def test_undo_before_a_review_is_started_says_so(self):
        self.login(self.rachel)
        r = self.client.post(self.url + "undo/", {"version": 1}, format="json")
        assert (r.status_code, r.json()["detail"]) == (400, f"undo: you have not started a review of capture {self.capture.pk}")


class ReviewHistoryPermissionsTestCase(ReviewHistoryBase):
    """Who may read a review's log and restore it: its annotator, reviewers and admins."""

    def test_another_annotator_may_neither_restore_nor_read_the_log(self):
        other = self.make_annotator("dora")
        self.login(other)
        event = ReviewEvent.objects.filter(review_id=self.review["id"]).first().pk
        assert self.restore(event).status_code == 403
        assert self.client.get(f"/api/captures/{self.capture.pk}/reviews/{self.review['id']}/events/").status_code == 403
        self.login(self.bob)
        assert shape(self.client.get(self.url).json()) == self.states[-1]

    def test_an_outsider_gets_404(self):
        self.login(self.charlie)
        event = ReviewEvent.objects.filter(review_id=self.review["id"]).first().pk
        assert self.restore(event).status_code == 404
        assert self.client.get(f"/api/captures/{self.capture.pk}/reviews/{self.review['id']}/events/").status_code == 404
        assert self.client.post(self.url + "undo/", {"version": 1}, format="json").status_code == 404

    def test_a_reviewer_restores_an_annotators_review_and_is_named_in_its_log(self):
        self.login(self.rachel)
        events = self.events()
        r = self.restore(events[2]["id"])
        assert r.status_code == 200, r.content
        assert shape(r.json()) == self.states[2]
        assert self.events()[-1]["user"] == "rachel"

    def test_a_review_of_another_capture_is_not_found(self):
        elsewhere = self.ready_capture(candidates=(50,), n_frames=100, name="d.bvh")
        url = f"/api/captures/{elsewhere.pk}/reviews/{self.review['id']}/restore/"
        r = self.client.post(url, {"event": 1, "version": self.review["version"]}, format="json")
        assert r.status_code == 404

    def make_annotator(self, name):
        from django.contrib.auth import get_user_model

        from segmentation import services

        user = get_user_model().objects.create_user(name, password=f"{name}-password")
        services.do_set_member(self.project, name, "annotator")
        return user
