"""The two error boundaries (the job guard and the API's translator) take only domain errors
(motionlib's and the service's) as the caller's fault. Anything else is a bug: it is logged with
its traceback and reported as an internal error with a reference the user can quote."""

import re
from unittest import mock

from django.db.models.signals import pre_save

from motionlib.errors import CaptureError
from segmentation import services
from segmentation.errors import Invalid
from segmentation.models import DetectionRun, Label
from segmentation.services import adaptation
from tests.segmentation.base import BaseTestCase, synthetic_bvh

REFERENCE = re.compile(r"reference ([0-9a-f]{8})")

class JobGuardTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.bob)

    def test_it_stores_a_bare_value_error_in_detection_as_an_internal_error_with_a_reference(self):
        numpy_bug = ValueError("operands could not be broadcast together with shapes (3,) (4,)")
        with mock.patch.object(adaptation, "detect", side_effect=numpy_bug), \
                self.assertLogs("segmentation.services.jobs", "ERROR") as logs:
            capture = self.ingest(self.upload(synthetic_bvh(), name="take.bvh").json()["id"])
        run = DetectionRun.objects.get(capture=capture)
        self.assertEqual(run.status, "failed")
        self.assertNotIn("broadcast", run.error)  # not shown as a fault of the studio's file
        self.assertIn("Detection failed with an internal error", run.error)
        reference = REFERENCE.search(run.error).group(1)
        [record] = logs.records
        self.assertIn(reference, record.getMessage())
        self.assertIs(record.exc_info[1], numpy_bug)  # the traceback is logged beside it

    def test_it_stores_a_domain_error_in_detection_as_it_is(self):
        fault = CaptureError("frame 12 has no motion", path="take.bvh", line=40)
        with mock.patch.object(adaptation, "detect", side_effect=fault):
            capture = self.ingest(self.upload(synthetic_bvh(), name="take.bvh").json()["id"])
        run = DetectionRun.objects.get(capture=capture)
        self.assertEqual((run.status, run.error), ("failed", "take.bvh:40: frame 12 has no motion"))

class TranslatorTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.bob)
        self.capture = self.ready_capture()

    def start_run(self):
        return self.client.post(f"/api/captures/{self.capture.pk}/runs/",
                                {"method": "bone_angle", "params": {}}, format="json")

    def test_it_answers_a_bare_value_error_with_500_and_a_reference(self):
        numpy_bug = ValueError("zero-size array to reduction operation maximum")
        with mock.patch.object(services, "do_start_run", side_effect=numpy_bug), \
                self.assertLogs("segmentation.api.common.errors", "ERROR") as logs:
            response = self.start_run()
        self.assertEqual(response.status_code, 500)
        body = response.json()
        self.assertEqual(set(body), {"detail", "reference"})
        self.assertEqual(body["detail"], "internal error")
        [record] = logs.records
        self.assertIn(body["reference"], record.getMessage())
        self.assertIs(record.exc_info[1], numpy_bug)

    def test_it_answers_a_domain_error_with_400_and_its_message(self):
        with mock.patch.object(services, "do_start_run", side_effect=Invalid("method: no such method")):
            response = self.start_run()
        self.assertEqual(response.status_code, 400)
        self.assertEqual(response.json(), {"detail": "method: no such method",
                                           "method": ["no such method"]})

class DuplicateLabelTestCase(BaseTestCase):
    def test_it_refuses_a_label_added_meanwhile_by_another_request_with_a_400(self):
        # Another request stores the same label between this one's check and its insert.
        def meanwhile(sender, instance, **kwargs):
            pre_save.disconnect(meanwhile, sender=Label)
            Label.objects.create(project=instance.project, name=instance.name, position=9)

        pre_save.connect(meanwhile, sender=Label)
        self.addCleanup(pre_save.disconnect, meanwhile, sender=Label)
        self.login(self.alice)
        response = self.client.post(f"/api/projects/{self.project.pk}/labels/", {"name": "squat"},
                                    format="json")
        self.assertEqual(response.status_code, 400)
        self.assertEqual(response.json()["detail"], "name: the project already has a label 'squat'")
