import re

from django.contrib.auth import get_user_model

from tests.segmentation.base import BaseTestCase

MODELS = ("project", "membership", "label", "capture", "detectionrun", "review", "cut",
          "segmentlabel", "reviewevent")


class AdminTestCase(BaseTestCase):
    def test_every_model_has_a_working_admin_list_and_change_page(self):
        capture = self.ready_capture()
        self.login(self.bob)
        self.client.get(f"/api/captures/{capture.pk}/review/")
        self.client.patch(
            f"/api/captures/{capture.pk}/review/segments/0/", {"label": "walk", "version": 1}, format="json"
        )
        staff = get_user_model().objects.create_superuser("root", password="root-password")
        self.client.force_login(staff)
        for model in MODELS:
            r = self.client.get(f"/admin/segmentation/{model}/")
            self.assertEqual(r.status_code, 200, model)
            first = re.search(rf'href="/admin/segmentation/{model}/(\d+)/change/', r.content.decode())
            self.assertIsNotNone(first, f"no {model} row listed")
            self.assertEqual(self.client.get(f"/admin/segmentation/{model}/{first[1]}/change/").status_code, 200, model)
