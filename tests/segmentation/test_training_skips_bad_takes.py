"""A reviewed take a training cannot learn from (too short to analyse, unreadable) is left
out with a note naming it, never failing the project's training (issue 48, item 3: one
submitted 3-frame BVH or CSV failed every later training of its project until a reviewer
returned that review). With real workers: tests/segmentation/integration/
test_adaptation_flow.py."""

from django.core.files.uploadedfile import SimpleUploadedFile

from segmentation import services
from segmentation.models import ProjectCutModel
from tests.segmentation.base import ingested, synthetic_bvh
from tests.segmentation.test_model_gate import GateTestCase


def three_frame_bvh():
    """A synthetic BVH take cut to its first three frames."""
    head, motion = synthetic_bvh(seed=5, duration=5.0).decode().split("MOTION\n")
    lines = motion.splitlines()
    frame_time = next(line for line in lines if line.startswith("Frame Time"))
    rows = [line for line in lines if line and not line.startswith(("Frames", "Frame Time"))][:3]
    return f"{head}MOTION\nFrames: 3\n{frame_time}\n" + "\n".join(rows) + "\n"


THREE_FRAME_CSV = b"frame,a_x,a_y,a_z,b_x,b_y,b_z\n0,1,2,3,4,5,6\n1,1,2,3,4,5,7\n2,1,2,3,4,5,8\n"


class BadTakeTestCase(GateTestCase):
    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        cls.good = cls.reviewed([51, 52], cls.bob)
        cls.short = [ingested(cls.project, cls.dave, SimpleUploadedFile(name, content))
                     for name, content in (("short.bvh", three_frame_bvh().encode()),
                                           ("short.csv", THREE_FRAME_CSV))]
        for capture in cls.short:
            assert capture.status == "ready", capture.error
            review = services.get_or_create_review(capture, cls.dave)
            services.do_submit_review(review, cls.dave, review.version)
        cls.job = cls.train()
        cls.again = cls.train()

    def test_the_training_learns_from_the_other_takes(self):
        self.assertEqual((self.job.status, self.job.version, self.job.n_takes), ("ready", 1, 2))
        self.assertEqual(self.job.trained_on, [c.pk for c in self.good])

    def test_it_names_each_skipped_take_and_why(self):
        lines = self.job.skipped.splitlines()
        self.assertEqual(len(lines), 2, lines)
        for capture, line in zip(self.short, lines, strict=True):
            self.assertTrue(line.startswith(f"capture {capture.pk} ({capture.name!r}) skipped: "), line)
            self.assertIn("too short", line)

    def test_the_next_training_succeeds_too(self):
        self.assertEqual((self.again.status, self.again.n_takes), ("ready", 2))
        self.assertEqual([line.split(" skipped: ")[0] for line in self.again.skipped.splitlines()],
                         [f"capture {c.pk} ({c.name!r})" for c in self.short])
        self.assertFalse(ProjectCutModel.objects.filter(project=self.project, status="failed").exists())

    def test_a_reviewer_sees_which_takes_were_skipped(self):
        self.login(self.rachel)
        adapted = self.client.get(f"/api/captures/{self.good[0].pk}/review/").json()["adaptation"]
        self.assertEqual(adapted["training_skipped"], self.again.skipped)
        self.assertIsNone(adapted["training_error"])

    def test_an_annotator_does_not(self):
        self.login(self.bob)
        adapted = self.client.get(f"/api/captures/{self.good[0].pk}/review/").json()["adaptation"]
        self.assertIsNone(adapted["training_skipped"])
