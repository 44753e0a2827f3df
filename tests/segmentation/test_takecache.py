"""Parsed takes cached beside their originals for retraining: the cache gives back exactly
what the parser read, and the original is parsed once."""

import dataclasses

import numpy as np

from motionlib import adapt, synth
from segmentation.files import takecache
from segmentation.files.storage import read_take
from tests.segmentation.base import BaseTestCase, synthetic_bvh


def assert_same_take(test, got, want):
    test.assertTrue(np.array_equal(got.channels, want.channels))
    test.assertEqual(got.channels.dtype, want.channels.dtype)
    for field in ("name", "format", "fps", "frame_time", "rest_pose_frame", "path"):
        test.assertEqual(getattr(got, field), getattr(want, field), field)
    a, b = got.skeleton, want.skeleton
    test.assertEqual((a.names, a.channels, a.rotation_orders), (b.names, b.channels, b.rotation_orders))
    test.assertTrue(np.array_equal(a.parents, b.parents) and np.array_equal(a.offsets, b.offsets))
    test.assertEqual(a.axes is None, b.axes is None)
    if a.axes is not None:
        test.assertTrue(np.array_equal(a.axes, b.axes))
    test.assertEqual(sorted(a.end_sites), sorted(b.end_sites))
    for joint, offset in b.end_sites.items():
        test.assertTrue(np.array_equal(a.end_sites[joint], offset))


class TakeCacheTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.alice)
        response = self.upload(synthetic_bvh(seed=7, duration=20.0), name="cached.bvh")
        self.capture = self.ingest(response.json()["id"])
        self.reads = 0

    def counting_read(self, capture):
        self.reads += 1
        return read_take(capture)

    def test_it_gives_back_exactly_the_parsed_take(self):
        parsed = takecache.read_cached(self.capture, self.counting_read)
        cached = takecache.read_cached(self.capture, self.counting_read)
        assert_same_take(self, cached, read_take(self.capture))
        assert_same_take(self, parsed, cached)

    def test_it_parses_the_original_once(self):
        for _ in range(3):
            takecache.read_cached(self.capture, self.counting_read)
        self.assertEqual(self.reads, 1)

    def test_it_keeps_asf_axes_and_end_sites(self):
        take, _ = synth.generate(seed=2, fps=120.0, duration=5.0)
        rng = np.random.default_rng(0)
        axes = np.linalg.qr(rng.normal(size=(take.skeleton.n_joints, 3, 3)))[0]
        skeleton = dataclasses.replace(take.skeleton, axes=axes, end_sites={2: np.array([0.5, 1.0, -2.0])})
        amc_like = dataclasses.replace(take, skeleton=skeleton, format="amc", rest_pose_frame=None)
        takecache.read_cached(self.capture, lambda capture: amc_like)
        assert_same_take(self, takecache.read_cached(self.capture, self.counting_read), amc_like)
        self.assertEqual(self.reads, 0)

    def test_a_project_model_learnt_from_cached_takes_is_the_same(self):
        cuts = [600, 1200]
        takecache.read_cached(self.capture, read_take)
        from_cache = takecache.read_cached(self.capture, read_take)
        self.assertEqual(adapt.fit_cut_model([(from_cache, cuts)]).to_json(),
                         adapt.fit_cut_model([(read_take(self.capture), cuts)]).to_json())

    def test_another_capture_of_the_same_file_elsewhere_has_its_own_cache(self):
        self.assertNotEqual(takecache.cache_names(self.capture),
                            takecache.cache_names(self.ready_capture()))
