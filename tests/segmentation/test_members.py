from tests.segmentation.base import BaseTestCase


class MembersTestCase(BaseTestCase):
    def url(self):
        return f"/api/projects/{self.project.pk}/members/"

    def test_admin_changes_a_members_role_at_once(self):
        self.login(self.alice)
        r = self.client.post(self.url(), {"username": "bob", "role": "reviewer"}, format="json")
        self.assertEqual((r.status_code, r.json()["role"]), (200, "reviewer"))
        self.assertEqual(self.project.role_of(self.bob), "reviewer")

    def test_annotator_cannot_add_members(self):
        self.login(self.bob)
        r = self.client.post(self.url(), {"username": "charlie", "role": "admin"}, format="json")
        self.assertEqual(r.status_code, 403)
        self.assertIsNone(self.project.role_of(self.charlie))

    def test_annotator_cannot_promote_themselves(self):
        self.login(self.bob)
        r = self.client.post(self.url(), {"username": "bob", "role": "admin"}, format="json")
        self.assertEqual(r.status_code, 403)
        self.assertEqual(self.project.role_of(self.bob), "annotator")

    def test_it_refuses_an_unknown_role(self):
        self.login(self.alice)
        r = self.client.post(self.url(), {"username": "charlie", "role": "boss"}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("role", r.json())

    def test_it_keeps_the_last_admin(self):
        self.login(self.alice)
        r = self.client.post(self.url(), {"username": "alice", "role": "annotator"}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("only admin", r.json()["detail"])

    def test_outsider_gets_404(self):
        self.login(self.charlie)
        self.assertEqual(self.client.get(self.url()).status_code, 404)
