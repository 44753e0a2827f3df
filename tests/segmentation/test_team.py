from django.contrib.auth import get_user_model

from segmentation.models import Membership
from tests.segmentation.base import BaseTestCase


class TeamTestCase(BaseTestCase):
    def member_url(self, user):
        return f"/api/projects/{self.project.pk}/members/{user.pk}/"

    def test_admin_changes_a_role(self):
        self.login(self.alice)
        r = self.client.patch(self.member_url(self.bob), {"role": "reviewer"}, format="json")
        self.assertEqual((r.status_code, r.json()["role"]), (200, "reviewer"))

    def test_admin_removes_a_member(self):
        self.login(self.alice)
        self.assertEqual(self.client.delete(self.member_url(self.bob)).status_code, 204)
        self.assertIsNone(self.project.role_of(self.bob))

    def test_it_refuses_to_demote_the_last_admin(self):
        self.login(self.alice)
        r = self.client.patch(self.member_url(self.alice), {"role": "reviewer"}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("last admin", r.json()["detail"])

    def test_it_refuses_to_remove_the_last_admin(self):
        self.login(self.alice)
        self.assertEqual(self.client.delete(self.member_url(self.alice)).status_code, 400)
        self.assertEqual(self.project.role_of(self.alice), "admin")

    def test_an_admin_may_step_down_when_another_admin_remains(self):
        Membership.objects.filter(project=self.project, user=self.rachel).update(role="admin")
        self.login(self.alice)
        r = self.client.patch(self.member_url(self.alice), {"role": "reviewer"}, format="json")
        self.assertEqual(r.status_code, 200)

    def test_reviewer_cannot_change_roles(self):
        self.login(self.rachel)
        r = self.client.patch(self.member_url(self.bob), {"role": "admin"}, format="json")
        self.assertEqual(r.status_code, 403)
        self.assertEqual(self.project.role_of(self.bob), "annotator")

    def test_annotator_cannot_list_members(self):
        self.login(self.bob)
        r = self.client.get(f"/api/projects/{self.project.pk}/members/")
        self.assertEqual(r.status_code, 403)


class NewAccountTestCase(BaseTestCase):
    url_suffix = "members/new-account/"

    def create(self, username="erin", role="annotator"):
        url = f"/api/projects/{self.project.pk}/{self.url_suffix}"
        return self.client.post(url, {"username": username, "role": role}, format="json")

    def test_a_project_admin_who_is_not_a_site_admin_cannot_create_accounts(self):
        self.login(self.alice)
        r = self.create()
        self.assertEqual(r.status_code, 403)
        self.assertFalse(get_user_model().objects.filter(username="erin").exists())

    def test_a_clash_and_a_new_name_answer_alike_to_a_project_admin(self):
        self.login(self.alice)
        self.assertEqual(self.create("charlie").json(), self.create("nobody-has-this").json())

    def test_a_site_admin_creates_an_account_with_a_one_time_password(self):
        self.alice.is_superuser = True
        self.alice.save()
        self.login(self.alice)
        r = self.create()
        self.assertEqual((r.status_code, r.json()["role"]), (201, "annotator"))
        erin = get_user_model().objects.get(username="erin")
        self.assertTrue(erin.check_password(r.json()["password"]))
        self.assertEqual(self.project.role_of(erin), "annotator")

    def test_a_site_admin_is_told_the_name_is_taken(self):
        self.alice.is_superuser = True
        self.alice.save()
        self.login(self.alice)
        r = self.create("charlie")
        self.assertEqual(r.status_code, 400)
        self.assertIn("already exists", r.json()["detail"])


class SchemaTestCase(BaseTestCase):
    def test_the_schema_documents_members_assignments_queue_and_return(self):
        self.login(self.bob)
        paths = self.client.get("/api/schema/", HTTP_ACCEPT="application/json").json()["paths"]
        for path, method in [
            ("/api/projects/{id}/members/{user_id}/", "patch"),
            ("/api/projects/{id}/members/new-account/", "post"),
            ("/api/projects/{id}/assignments/", "post"),
            ("/api/projects/{id}/assignments/{assignment_id}/", "delete"),
            ("/api/queue/", "get"),
            ("/api/captures/{id}/reviews/{review_id}/return/", "post"),
        ]:
            self.assertIn(method, paths[path], path)
