"""Label suggestions: computed by the worker's job and stored, never on a review request;
drawn only from what the review's annotator may see (gold and their own segments for an
annotator), never from another annotator's labels."""

import os
import sys
import threading

import numpy as np
import pytest
from django.core.files.base import ContentFile
from django.db import connection
from django.test import TransactionTestCase
from django.test.utils import CaptureQueriesContext

import motionlib
from motionlib import synth
from segmentation import services, tasks
from segmentation.files import storage
from segmentation.models import Capture, LabelSuggestion
from segmentation.services import gold
from segmentation.services.taxonomy import do_change_label
from segmentation.similar import proposals, suggestions
from tests.segmentation.test_library import LibraryTestCase, submit_review


class SuggestionsTestCase(LibraryTestCase):
    """Take A (seed 5) is the library; bob reviews take B (seed 6), cut at its true
    boundaries and not labelled."""

    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        for name in synth.ACTIONS:
            if name not in ("walk", "punch"):
                services.do_add_label(cls.project, name)

    def synth_capture(self, seed, duration):
        take, truth = synth.generate(seed=seed, fps=120.0, duration=duration)
        capture = Capture(
            project=self.project, uploaded_by=self.alice, name=f"synth-{seed}.bvh", format="bvh",
            checksum=f"synth-{seed}-{duration}", status="ready", fps=take.fps,
            n_frames=take.n_frames, n_joints=len(take.skeleton.names),
            skeleton={"joints": list(take.skeleton.names),
                      "parents": [int(p) for p in take.skeleton.parents], "height": 1.7, "up": "y"},
        )
        capture.original.save("take.bvh", ContentFile(b"HIERARCHY"), save=False)
        positions = np.asarray(motionlib.forward_kinematics(take), dtype="<f4")
        storage.save_npy(capture.positions, "positions.npy", positions)
        capture.save()
        return capture, truth

    def setUp(self):
        super().setUp()
        self.take_a, self.truth_a = self.synth_capture(5, 40.0)
        self.take_b, self.truth_b = self.synth_capture(6, 30.0)

    def submit_take_a(self, user):
        cuts = [start for start, _, _ in self.truth_a[1:]]
        return submit_review(self.take_a, user, cuts, [label for _, _, label in self.truth_a])

    def review_take_b(self, user):
        review = services.get_or_create_review(self.take_b, user)
        for start, _, _ in self.truth_b[1:]:
            review = services.do_insert_cut(review, user, start, review.version)
        return review

    def suggested(self, user):
        """{(start, stop): label} once the worker's job has run."""
        tasks.suggest(self.take_b.pk, user.pk)
        body = suggestions.for_review(self.take_b, user)
        assert body["pending"] is False
        return {(s["start"], s["stop"]): s["label"] for s in body["suggestions"]}


class SuggestionPoolTest(SuggestionsTestCase):
    def test_it_suggests_from_the_annotators_own_segments(self):
        self.submit_take_a(self.bob)
        self.review_take_b(self.bob)
        found = self.suggested(self.bob)
        truth = {(start, stop): label for start, stop, label in self.truth_b}
        assert set(found) == set(truth)
        hits = sum(found[span] == truth[span] for span in truth)
        assert hits >= len(truth) - 1, (found, truth)

    def test_it_never_suggests_from_another_annotators_segments(self):
        self.submit_take_a(self.dana)
        # Bob's own library: take C, every segment labelled "idle".
        take_c, truth_c = self.synth_capture(7, 20.0)
        submit_review(take_c, self.bob, [start for start, _, _ in truth_c[1:]], ["idle"] * len(truth_c))
        self.review_take_b(self.bob)
        assert set(self.suggested(self.bob).values()) == {"idle"}

    def test_it_never_suggests_a_retired_label(self):
        take_c, truth_c = self.synth_capture(7, 20.0)
        submit_review(take_c, self.bob, [start for start, _, _ in truth_c[1:]], ["idle"] * len(truth_c))
        self.submit_take_a(self.bob)
        self.review_take_b(self.bob)
        assert "idle" in set(self.suggested(self.bob).values())
        do_change_label(self.project.labels.get(name="idle"), retired=True)
        found = self.suggested(self.bob)
        assert found and "idle" not in set(found.values())

    def test_it_suggests_nothing_when_the_annotator_may_see_no_segment(self):
        self.submit_take_a(self.dana)
        self.review_take_b(self.bob)
        assert self.suggested(self.bob) == {}

    def test_it_suggests_gold_segments_to_an_annotator(self):
        self.submit_take_a(self.dana)
        gold.do_save_gold(self.take_a, self.rachel, [start for start, _, _ in self.truth_a[1:]],
                             [label for _, _, label in self.truth_a], version=0)
        self.review_take_b(self.bob)
        assert None not in self.suggested(self.bob).values()

    def test_annotators_who_see_the_same_segments_share_the_stored_suggestions(self):
        self.submit_take_a(self.dana)
        gold.do_save_gold(self.take_a, self.rachel, [start for start, _, _ in self.truth_a[1:]],
                             [label for _, _, label in self.truth_a], version=0)
        # Bob and charlie (now an annotator) have no segment of their own: gold only.
        services.do_set_member(self.project, "charlie", "annotator")
        self.review_take_b(self.bob)
        self.review_take_b(self.charlie)
        assert tasks.suggest(self.take_b.pk, self.bob.pk) == len(self.truth_b)
        assert tasks.suggest(self.take_b.pk, self.charlie.pk) == 0
        assert self.suggested(self.charlie) == self.suggested(self.bob)

    def test_a_reviewer_gets_suggestions_from_every_segment_they_may_see(self):
        self.submit_take_a(self.dana)
        self.review_take_b(self.rachel)
        assert None not in self.suggested(self.rachel).values()

    def test_it_refuses_the_suggestions_of_a_capture_to_an_outsider(self):
        self.login(self.charlie)
        response = self.client.get(f"/api/captures/{self.take_b.pk}/review/suggestions/")
        assert response.status_code == 404


class SuggestionStoreTest(SuggestionsTestCase):
    def setUp(self):
        super().setUp()
        self.submit_take_a(self.bob)
        self.review = self.review_take_b(self.bob)
        self.login(self.bob)
        self.url = f"/api/captures/{self.take_b.pk}/review/"

    def test_it_computes_no_suggestion_on_a_review_request(self):
        with CaptureQueriesContext(connection) as queries:
            review = self.client.get(self.url).json()
            self.client.patch(self.url + "segments/1/", {"label": "walk", "version": review["version"]},
                              format="json")
        touched = [q["sql"] for q in queries if "librarysegment" in q["sql"] or "suggestion" in q["sql"]]
        assert touched == []
        assert "suggested_label" not in review["segments"][0]

    def test_the_page_gets_suggestions_once_the_worker_stored_them(self):
        first = self.client.get(self.url + "suggestions/").json()
        assert first == {"pending": True, "suggestions": []}
        tasks.suggest(self.take_b.pk, self.bob.pk)
        body = self.client.get(self.url + "suggestions/").json()
        assert body["pending"] is False
        assert [(s["start"], s["stop"]) for s in body["suggestions"]] == [
            (start, stop) for start, stop, _ in self.truth_b]

    def test_it_sends_one_job_until_that_job_is_done(self):
        with self.captureOnCommitCallbacks() as sent:
            suggestions.for_review(self.take_b, self.bob)
            suggestions.for_review(self.take_b, self.bob)
        assert len(sent) == 1
        tasks.suggest(self.take_b.pk, self.bob.pk)
        services.do_insert_cut(self.review, self.bob, 100, self.review.version)
        with self.captureOnCommitCallbacks() as sent:
            assert suggestions.for_review(self.take_b, self.bob)["pending"] is True
        assert len(sent) == 1

    def test_an_edit_needs_suggestions_only_for_the_spans_it_creates(self):
        assert tasks.suggest(self.take_b.pk, self.bob.pk) == len(self.truth_b)
        assert tasks.suggest(self.take_b.pk, self.bob.pk) == 0
        services.do_insert_cut(self.review, self.bob, 100, self.review.version)
        assert tasks.suggest(self.take_b.pk, self.bob.pk) == 2

    def test_a_change_to_the_pool_makes_stored_suggestions_stale(self):
        tasks.suggest(self.take_b.pk, self.bob.pk)
        take_c, truth_c = self.synth_capture(7, 20.0)
        submit_review(take_c, self.bob, [start for start, _, _ in truth_c[1:]],
                      [label for _, _, label in truth_c])
        assert suggestions.for_review(self.take_b, self.bob)["pending"] is True
        assert tasks.suggest(self.take_b.pk, self.bob.pk) == len(self.truth_b)
        # the old pool's suggestions and its proposals (``similar.proposals``) are gone
        library = LabelSuggestion.objects.exclude(pool__startswith=proposals.PREFIX)
        assert library.count() == len(self.truth_b)
        assert LabelSuggestion.objects.count() - library.count() == len(self.truth_b)


class LowPriorityTest(TransactionTestCase):
    """The job computes at a raised nice value, in a thread, so the priority of the
    worker process (and of its next job) stays as it was; it writes at its own."""

    def test_it_computes_at_a_lower_priority_and_leaves_the_workers_own_priority_alone(self):
        if sys.platform != "linux":
            pytest.skip("nice values per thread are a Linux feature")
        before = os.getpriority(os.PRIO_PROCESS, 0)
        seen = suggestions.at_low_priority(lambda: os.getpriority(os.PRIO_PROCESS, threading.get_native_id()))
        assert seen == min(before + suggestions.LOW_PRIORITY, 19)
        assert os.getpriority(os.PRIO_PROCESS, 0) == before

    def test_it_hands_the_jobs_error_back(self):
        with pytest.raises(ValueError, match="bad span"):
            suggestions.at_low_priority(lambda: (_ for _ in ()).throw(ValueError("bad span")))
