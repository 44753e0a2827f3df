"""Stored arrays are written once and moved into place (issue 50): what is read back is
what was stored, and no scratch file is left behind."""

import os
import stat

import numpy as np
from django.conf import settings
from django.core.files.storage import default_storage

from segmentation.files import storage
from segmentation.models import Capture
from tests.segmentation.base import BaseTestCase


class SaveNpyTestCase(BaseTestCase):
    def test_it_stores_the_array_readable_by_others_and_leaves_no_scratch_file(self):
        capture = self.ready_capture(n_frames=50, n_joints=4)
        array = np.random.default_rng(5).normal(size=(1000, 7, 3)).astype("<f4")
        storage.save_npy(capture.positions, "positions.npy", array)
        capture.save()
        np.testing.assert_array_equal(storage.load_npy(Capture.objects.get(pk=capture.pk).positions), array)
        path = default_storage.path(capture.positions.name)
        self.assertEqual(stat.S_IMODE(os.stat(path).st_mode), settings.FILE_UPLOAD_PERMISSIONS or 0o644)
        leftovers = [name for _, _, names in os.walk(settings.MEDIA_ROOT) for name in names
                     if name.startswith(".npy-")]
        self.assertEqual(leftovers, [])
