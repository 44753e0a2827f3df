"""Frames and signals answers: built once, revalidated by ETag, and at most
CUTROOM_HEAVY_REQUESTS built at once per process while light requests go through."""

import threading

import numpy as np
from django.test import override_settings

from segmentation.api.common import heavy
from segmentation.files import storage
from segmentation.models import DetectionRun
from tests.segmentation.base import BaseTestCase


class HeavyAnswersTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture(n_frames=400)
        self.frames = f"/api/captures/{self.capture.pk}/frames/?start=0&stop=100"
        self.signal = f"/api/captures/{self.capture.pk}/signal/?max_points=100"
        self.login(self.bob)

    def test_it_answers_304_to_the_etag_of_the_frames_it_sent(self):
        first = self.client.get(self.frames)
        again = self.client.get(self.frames, HTTP_IF_NONE_MATCH=first["ETag"])
        self.assertEqual(again.status_code, 304)
        self.assertEqual(again["ETag"], first["ETag"])
        self.assertEqual(again.content, b"")

    def test_it_answers_304_to_the_etag_of_the_signal_it_sent(self):
        first = self.client.get(self.signal)
        again = self.client.get(self.signal, HTTP_IF_NONE_MATCH=f'"other", {first["ETag"]}')
        self.assertEqual(again.status_code, 304)

    def test_it_tells_the_browser_to_keep_the_answer_and_ask_again(self):
        response = self.client.get(self.frames)
        self.assertEqual(response["Cache-Control"], "private, no-cache")

    def test_it_sends_the_whole_answer_to_an_etag_it_did_not_send(self):
        response = self.client.get(self.frames, HTTP_IF_NONE_MATCH='"not-this-one"')
        self.assertEqual(response.status_code, 200)
        self.assertEqual(response.json()["n_frames"], 100)

    def test_it_gives_other_frames_another_etag(self):
        first = self.client.get(self.frames)["ETag"]
        other = self.client.get(f"/api/captures/{self.capture.pk}/frames/?start=100&stop=200")["ETag"]
        self.assertNotEqual(first, other)

    def test_it_answers_a_second_reader_from_the_built_answer(self):
        first = self.client.get(self.frames).json()
        # A capture's positions are never rewritten; here the stored file is replaced under
        # the same name to show that the second reader's answer does not read it again.
        np.save(self.capture.positions.path, np.zeros((400, 5, 3), "<f4"))
        self.login(self.rachel)
        self.assertEqual(self.client.get(self.frames).json(), first)

    def test_it_answers_a_newer_run_with_its_own_signal(self):
        old = self.client.get(self.signal).json()
        run = DetectionRun.objects.create(capture=self.capture, method="bone_angle", status="ready",
                                          params={"param": 0.5}, candidates=[])
        storage.save_npz(run.signals, "signals.npz", {"q": np.ones(400)})
        run.save()
        new = self.client.get(self.signal).json()
        self.assertEqual((old["run"], new["run"]), (self.capture.runs.order_by("pk").first().pk, run.pk))
        self.assertEqual(set(new["signals"][0]["values"]), {1.0})

    def test_it_checks_who_may_see_the_capture_before_answering_from_the_cache(self):
        etag = self.client.get(self.frames)["ETag"]
        self.login(self.charlie)
        self.assertEqual(self.client.get(self.frames).status_code, 404)
        self.assertEqual(self.client.get(self.frames, HTTP_IF_NONE_MATCH=etag).status_code, 404)

    def test_it_keeps_no_answer_of_a_capture_that_is_not_ready(self):
        self.capture.status = "processing"
        self.capture.save()
        self.assertEqual(self.client.get(self.frames).status_code, 400)
        self.capture.status = "ready"
        self.capture.save()
        self.assertEqual(self.client.get(self.frames).status_code, 200)

    @override_settings(CUTROOM_HEAVY_REQUESTS=2, CUTROOM_HEAVY_WAIT=0)
    def test_it_lets_a_light_request_through_while_every_heavy_slot_is_held(self):
        with HeldSlots(2):
            light = self.client.get(f"/api/captures/{self.capture.pk}/")
            heavy_now = self.client.get(self.signal)
        self.assertEqual(light.status_code, 200)
        self.assertEqual(heavy_now.status_code, 429)
        self.assertIn("CUTROOM_HEAVY_REQUESTS", heavy_now.json()["detail"])
        self.assertEqual(self.client.get(self.signal).status_code, 200)

    @override_settings(CUTROOM_HEAVY_REQUESTS=2, CUTROOM_HEAVY_WAIT=0)
    def test_it_builds_a_heavy_answer_while_fewer_slots_than_the_limit_are_held(self):
        with HeldSlots(1):
            self.assertEqual(self.client.get(self.frames).status_code, 200)

    @override_settings(CUTROOM_HEAVY_REQUESTS=1, CUTROOM_HEAVY_WAIT=0)
    def test_it_serves_a_built_answer_while_every_heavy_slot_is_held(self):
        self.client.get(self.frames)
        with HeldSlots(1):
            self.assertEqual(self.client.get(self.frames).status_code, 200)


class HeldSlots:
    """``n`` threads, each holding one heavy slot until the block ends."""

    def __init__(self, n):
        self.n, self.release = n, threading.Event()

    def hold(self, held):
        with heavy.heavy_slot():
            held.release()
            self.release.wait()

    def __enter__(self):
        held = threading.Semaphore(0)
        self.threads = [threading.Thread(target=self.hold, args=(held,)) for _ in range(self.n)]
        for thread in self.threads:
            thread.start()
        for _ in range(self.n):
            held.acquire()

    def __exit__(self, *exc):
        self.release.set()
        for thread in self.threads:
            thread.join()


class AnswerCacheTestCase(BaseTestCase):
    def test_it_builds_an_answer_once_for_threads_that_ask_together(self):
        cache, builds, go = heavy.AnswerCache(2**20), [], threading.Event()

        def build():
            builds.append(1)
            go.wait()
            return heavy.Answer(b"{}", "application/json")

        got = []
        threads = [threading.Thread(target=lambda: got.append(cache.get_or_build("k", build)))
                   for _ in range(8)]
        for thread in threads:
            thread.start()
        go.set()
        for thread in threads:
            thread.join()
        self.assertEqual((len(builds), len({id(a) for a in got})), (1, 1))

    def test_it_drops_the_least_recently_used_answer_beyond_its_size(self):
        cache = heavy.AnswerCache(12)
        for key in "abc":
            cache.put(key, heavy.Answer(b"1234", "text/plain"))
        cache.get("a")
        cache.put("d", heavy.Answer(b"1234", "text/plain"))
        self.assertEqual(list(cache.answers), ["c", "a", "d"])
        self.assertEqual(cache.size, 12)
