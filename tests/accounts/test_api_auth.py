from tests.segmentation.base import BaseTestCase


class AnonymousApiTestCase(BaseTestCase):
    def test_it_answers_an_anonymous_call_with_401_and_how_to_authenticate(self):
        r = self.client.get("/api/captures/")
        self.assertEqual(r.status_code, 401)
        self.assertEqual(r["WWW-Authenticate"], "Token")
        self.assertIn("credentials were not provided", r.json()["detail"])

    def test_it_answers_an_anonymous_write_with_401(self):
        r = self.client.post("/api/projects/", {"name": "x"}, format="json")
        self.assertEqual((r.status_code, r["WWW-Authenticate"]), (401, "Token"))

    def test_it_answers_an_unknown_token_with_401(self):
        self.client.credentials(HTTP_AUTHORIZATION="Token 0123456789abcdef")
        r = self.client.get("/api/me/")
        self.assertEqual((r.status_code, r["WWW-Authenticate"]), (401, "Token"))

    def test_a_signed_in_member_without_the_role_still_gets_403(self):
        self.login(self.bob)
        r = self.client.post(f"/api/projects/{self.project.pk}/labels/", {"name": "x"}, format="json")
        self.assertEqual(r.status_code, 403)
