from tests.segmentation.base import BaseTestCase


class LabelsTestCase(BaseTestCase):
    def url(self):
        return f"/api/projects/{self.project.pk}/labels/"

    def test_admin_adds_a_label(self):
        self.login(self.alice)
        r = self.client.post(self.url(), {"name": "squat", "color": "#16A34A", "hotkey": "3"}, format="json")
        self.assertEqual(r.status_code, 201)
        self.assertEqual(r.json()["color"], "#16a34a")
        self.assertEqual([x["name"] for x in self.client.get(self.url()).json()], ["walk", "punch", "squat"])

    def test_annotator_cannot_add_labels(self):
        self.login(self.bob)
        r = self.client.post(self.url(), {"name": "squat"}, format="json")
        self.assertEqual(r.status_code, 403)
        self.assertFalse(self.project.labels.filter(name="squat").exists())

    def test_reviewer_cannot_add_labels(self):
        self.login(self.rachel)
        self.assertEqual(self.client.post(self.url(), {"name": "squat"}, format="json").status_code, 403)

    def test_outsider_gets_404(self):
        self.login(self.charlie)
        self.assertEqual(self.client.post(self.url(), {"name": "squat"}, format="json").status_code, 404)

    def test_it_refuses_a_used_hotkey(self):
        self.login(self.alice)
        r = self.client.post(self.url(), {"name": "squat", "hotkey": "1"}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("'1' is already used", r.json()["hotkey"][0])

    def test_it_refuses_a_duplicate_name(self):
        self.login(self.alice)
        r = self.client.post(self.url(), {"name": "walk"}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("already has a label 'walk'", r.json()["detail"])

    def test_it_refuses_a_bad_colour(self):
        self.login(self.alice)
        r = self.client.post(self.url(), {"name": "squat", "color": "green"}, format="json")
        self.assertIn("#rrggbb, got 'green'", r.json()["color"][0])
