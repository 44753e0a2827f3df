from tests.segmentation.base import BaseTestCase


class TaxonomyTestCase(BaseTestCase):
    def url(self, suffix=""):
        return f"/api/projects/{self.project.pk}/labels/{suffix}"

    def change(self, label, **fields):
        return self.client.patch(self.url(f"{label.pk}/"), fields, format="json")

    def test_admin_renames_and_recolours_a_label(self):
        self.login(self.alice)
        r = self.change(self.walk, name="stroll", color="#00AA00")
        self.assertEqual((r.json()["name"], r.json()["color"]), ("stroll", "#00aa00"))

    def test_a_rename_shows_on_existing_segments(self):
        capture = self.ready_capture()
        self.login(self.bob)
        url = f"/api/captures/{capture.pk}/review/"
        self.client.post(url)
        self.client.patch(url + "segments/0/", {"label": "walk", "version": 1}, format="json")
        self.login(self.alice)
        self.change(self.walk, name="stroll")
        self.login(self.bob)
        self.assertEqual(self.client.get(url).json()["segments"][0]["label"], "stroll")

    def test_it_refuses_a_name_already_used(self):
        self.login(self.alice)
        r = self.change(self.walk, name="punch")
        self.assertEqual(r.status_code, 400)
        self.assertIn("punch", r.json()["detail"])

    def test_it_refuses_a_hotkey_already_used(self):
        self.login(self.alice)
        r = self.change(self.walk, hotkey="2")
        self.assertEqual(r.status_code, 400)
        self.assertIn("punch", r.json()["detail"])

    def test_it_reorders_labels(self):
        self.login(self.alice)
        r = self.client.post(self.url("order/"), {"order": [self.punch.pk, self.walk.pk]}, format="json")
        self.assertEqual([label["name"] for label in r.json()], ["punch", "walk"])
        project = self.client.get(f"/api/projects/{self.project.pk}/").json()
        self.assertEqual([label["name"] for label in project["labels"]], ["punch", "walk"])

    def test_it_refuses_an_order_missing_a_label(self):
        self.login(self.alice)
        r = self.client.post(self.url("order/"), {"order": [self.punch.pk]}, format="json")
        self.assertEqual(r.status_code, 400)

    def test_a_retired_label_stays_on_segments_but_cannot_be_applied(self):
        capture = self.ready_capture()
        self.login(self.bob)
        url = f"/api/captures/{capture.pk}/review/"
        self.client.post(url)
        self.client.patch(url + "segments/0/", {"label": "walk", "version": 1}, format="json")
        self.login(self.alice)
        self.assertTrue(self.change(self.walk, retired=True).json()["retired"])
        self.login(self.bob)
        self.assertEqual(self.client.get(url).json()["segments"][0]["label"], "walk")
        r = self.client.patch(url + "segments/1/", {"label": "walk", "version": 2}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("retired", r.json()["detail"])

    def test_reviewer_cannot_edit_labels(self):
        self.login(self.rachel)
        self.assertEqual(self.change(self.walk, name="x").status_code, 403)
