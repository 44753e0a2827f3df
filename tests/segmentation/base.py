"""Personas and helpers shared by the service tests.

alice owns the project (admin), bob annotates, rachel reviews, charlie is an outsider
with a project of his own.
"""

import functools
import io

import numpy as np
from django.contrib.auth import get_user_model
from django.core.files.base import ContentFile
from django.core.files.uploadedfile import SimpleUploadedFile
from django.test import TestCase
from rest_framework.test import APIClient

from motionlib.shared_data import data_dir
from segmentation import services, tasks
from segmentation.files import storage
from segmentation.models import Capture, DetectionRun

SHARED_DATA = data_dir()


@functools.cache
def synthetic_bvh(seed=0, **kwargs):
    """Bytes of a seeded synthetic BVH take with known boundaries (made once per test
    process for each seed and settings: the same ones give the same bytes)."""
    from motionlib import synth, write_bvh

    take, _segments = synth.generate(seed=seed, fps=120.0, **kwargs)
    text = io.StringIO()
    write_bvh(take, text)
    return text.getvalue().encode()


def ingested(project, user, upload, asf=None):
    """``upload`` (with its ``asf`` skeleton for an AMC) uploaded to ``project`` by ``user``,
    then ingested and its default detection run by the service's own task functions, here
    in-process as a worker would; the capture, ready."""
    capture, _ = services.do_upload_capture(project, user, upload, asf=asf)
    tasks.ingest(capture.pk)
    for run in DetectionRun.objects.filter(capture=capture, status="queued"):
        tasks.detect(run.pk)
    capture = Capture.objects.get(pk=capture.pk)
    assert capture.status == "ready", capture.error
    return capture


class BaseTestCase(TestCase):
    @classmethod
    def setUpTestData(cls):
        users = get_user_model().objects
        cls.alice = users.create_user("alice", password="alice-password")
        cls.bob = users.create_user("bob", password="bob-password")
        cls.rachel = users.create_user("rachel", password="rachel-password")
        cls.charlie = users.create_user("charlie", password="charlie-password")
        cls.project = services.do_create_project(cls.alice, "Studio A")
        services.do_set_member(cls.project, "bob", "annotator")
        services.do_set_member(cls.project, "rachel", "reviewer")
        cls.walk = services.do_add_label(cls.project, "walk", "#2563eb", "1")
        cls.punch = services.do_add_label(cls.project, "punch", "#dc2626", "2")
        cls.other_project = services.do_create_project(cls.charlie, "Charlie's studio")

    def setUp(self):
        self.client = APIClient()

    def login(self, user):
        self.client.force_authenticate(user)

    def upload(self, content, name="take.bvh", project=None, asf=None):
        data = {"project": (project or self.project).pk, "file": SimpleUploadedFile(name, content)}
        if asf is not None:
            data["asf"] = SimpleUploadedFile(asf[0], asf[1])
        return self.client.post("/api/captures/", data, format="multipart")

    def ingest(self, capture_id):
        """Run the worker's jobs in-process: ingest, then the default detection run."""
        tasks.ingest(capture_id)
        for run in DetectionRun.objects.filter(capture_id=capture_id, status="queued"):
            tasks.detect(run.pk)
        return Capture.objects.get(pk=capture_id)

    def ready_capture(self, candidates=(100, 200, 300), n_frames=400, n_joints=5, name="c.bvh"):
        """A ready capture with a finished run, built directly (no file parsing).

        The review workflow does not depend on the parser; this keeps its tests small.
        """
        capture = Capture.objects.create(
            project=self.project, uploaded_by=self.alice, name=name, format="bvh",
            checksum=f"{name}-{n_frames}-{candidates}", status="ready", fps=120.0,
            n_frames=n_frames, n_joints=n_joints,
            skeleton={"joints": [f"j{i}" for i in range(n_joints)],
                      "parents": [-1] + list(range(n_joints - 1)), "height": 1.7, "up": "y"},
        )
        capture.original.save(name, ContentFile(b"HIERARCHY"), save=False)
        positions = np.arange(n_frames * n_joints * 3, dtype="<f4").reshape(n_frames, n_joints, 3)
        storage.save_npy(capture.positions, "positions.npy", positions)
        capture.save()
        run = DetectionRun.objects.create(
            capture=capture, method="bone_angle", params={"param": 0.5}, status="ready",
            candidates=[{"frame": f, "confidence": 0.5 + i / 10} for i, f in enumerate(candidates)],
        )
        signal = np.linspace(0.0, 1.0, n_frames)
        storage.save_npz(run.signals, "signals.npz", {"q": signal})
        run.save()
        return capture
