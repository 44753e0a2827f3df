"""Ingest computes a take's world positions once: it stores them, and the default
detection that follows in the same worker uses them instead of computing them again."""

import tempfile
from pathlib import Path
from unittest import mock

import motionlib
from segmentation.services import importing
from tests.segmentation.base import BaseTestCase, synthetic_bvh


class IngestPositionsTest(BaseTestCase):
    def test_it_computes_the_positions_once_for_ingest_and_detection(self):
        path = Path(self.enterContext(tempfile.TemporaryDirectory())) / "take.bvh"
        path.write_bytes(synthetic_bvh(seed=9, duration=30.0))
        outcome = importing.import_file(self.project, self.bob, path)
        with mock.patch.object(motionlib, "forward_kinematics",
                               wraps=motionlib.forward_kinematics) as computed:
            capture = self.ingest(outcome.capture.pk)
        assert capture.status == "ready", capture.error
        assert len(capture.latest_finished_run().candidates) > 0
        assert computed.call_count == 1
