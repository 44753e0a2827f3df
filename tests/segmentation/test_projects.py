from segmentation.models import Membership
from tests.segmentation.base import BaseTestCase


class ProjectsTestCase(BaseTestCase):
    def test_it_lists_only_the_callers_projects_with_role_and_labels(self):
        self.login(self.bob)
        projects = self.client.get("/api/projects/").json()
        self.assertEqual([p["name"] for p in projects], ["Studio A"])
        self.assertEqual(projects[0]["role"], "annotator")
        self.assertEqual(
            projects[0]["labels"][0], {"id": self.walk.pk, "name": "walk", "color": "#2563eb", "hotkey": "1",
             "position": 0, "retired": False}
        )

    def test_it_makes_the_creator_admin(self):
        self.login(self.bob)
        r = self.client.post("/api/projects/", {"name": "Bob's own"}, format="json")
        self.assertEqual(r.status_code, 201)
        self.assertEqual(Membership.objects.get(project_id=r.json()["id"], user=self.bob).role, "admin")

    def test_it_refuses_garbage_default_params(self):
        self.login(self.bob)
        r = self.client.post(
            "/api/projects/", {"name": "x", "default_method": "bone_angle", "default_params": {"param": 7}},
            format="json",
        )
        self.assertEqual(r.status_code, 400)
        self.assertIn("param", r.json()["params"])

    def test_outsider_gets_404(self):
        self.login(self.charlie)
        self.assertEqual(self.client.get(f"/api/projects/{self.project.pk}/").status_code, 404)
        self.assertEqual(self.client.get(f"/api/projects/{self.project.pk}/labels/").status_code, 404)

    def test_me_lists_memberships(self):
        self.login(self.rachel)
        me = self.client.get("/api/me/").json()
        self.assertEqual(me["username"], "rachel")
        self.assertEqual(me["projects"], [{"id": self.project.pk, "name": "Studio A", "role": "reviewer"}])


class ProjectIsolationTestCase(BaseTestCase):
    def test_an_annotator_cannot_see_a_project_they_are_not_in(self):
        self.login(self.charlie)
        theirs = self.upload(b"HIERARCHY\n", name="secret.bvh", project=self.other_project).json()
        self.login(self.bob)
        self.assertEqual(self.client.get(f"/api/projects/{self.other_project.pk}/").status_code, 404)
        self.assertEqual(self.client.get(f"/api/captures/{theirs['id']}/").status_code, 404)
        self.assertEqual(self.client.get(f"/api/captures/{theirs['id']}/frames/").status_code, 404)
        names = [c["name"] for c in self.client.get("/api/captures/").json()["results"]]
        self.assertNotIn("secret.bvh", names)
        r = self.upload(b"HIERARCHY\n", name="sneaky.bvh", project=self.other_project)
        self.assertEqual(r.status_code, 404)


class ProjectUpdateTestCase(BaseTestCase):
    def url(self):
        return f"/api/projects/{self.project.pk}/"

    def test_admin_sets_the_default_method_and_params(self):
        self.login(self.alice)
        r = self.client.patch(self.url(), {"default_method": "bone_angle", "default_params": {"param": "0.25"}}, format="json")
        self.assertEqual(r.status_code, 200)
        self.assertEqual((r.json()["default_method"], r.json()["default_params"]), ("bone_angle", {"param": 0.25}))

    def test_it_refuses_params_the_method_does_not_take(self):
        self.login(self.alice)
        r = self.client.patch(self.url(), {"default_method": "bone_angle", "default_params": {"window": 3}}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("window", r.json()["params"])
        self.project.refresh_from_db()
        self.assertEqual(self.project.default_method, "")

    def test_annotator_cannot_change_the_project(self):
        self.login(self.bob)
        r = self.client.patch(self.url(), {"name": "Bob's now"}, format="json")
        self.assertEqual(r.status_code, 403)
        self.project.refresh_from_db()
        self.assertEqual(self.project.name, "Studio A")

    def test_outsider_gets_404(self):
        self.login(self.charlie)
        self.assertEqual(self.client.patch(self.url(), {"name": "mine"}, format="json").status_code, 404)

    def test_renaming_keeps_the_defaults(self):
        self.login(self.alice)
        self.client.patch(self.url(), {"default_method": "bone_angle"}, format="json")
        self.client.patch(self.url(), {"name": "Studio B"}, format="json")
        self.project.refresh_from_db()
        self.assertEqual((self.project.name, self.project.default_method), ("Studio B", "bone_angle"))
