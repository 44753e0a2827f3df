"""Project and label names are shown to other people, so they are held to the rule usernames
are: nothing invisible, no direction marks, no look-alike letters passing for Latin ones;
an invitation shows the project name cleaned and short, so a project cannot be named to
carry a message (issue 48, item 12)."""

from django.contrib.auth import get_user_model

from segmentation.models import Invitation, Project
from tests.segmentation.base import BaseTestCase

DECEPTIVE = {
    "zero-width space": "walk\u200bfast",
    "right-to-left override": "walk\u202egpj.exe",
    "direction mark": "\u200fpunch",
    "Cyrillic a inside a Latin word": "p\u0430ypal",
    "only Cyrillic letters drawn as Latin": "\u0430\u0441\u0435",
    "no-break space": "walk\u00a0fast",
    "line separator": "walk\u2028fast",
}


class DeceptiveNamesTestCase(BaseTestCase):
    def test_it_refuses_them_in_project_names(self):
        self.login(self.alice)
        for what, name in DECEPTIVE.items():
            with self.subTest(what):
                r = self.client.post("/api/projects/", {"name": name}, format="json")
                self.assertEqual(r.status_code, 400, r.content)
                self.assertIn("name", r.json()["detail"])
                r = self.client.patch(f"/api/projects/{self.project.pk}/", {"name": name}, format="json")
                self.assertEqual(r.status_code, 400, r.content)
        self.assertEqual(Project.objects.get(pk=self.project.pk).name, "Studio A")

    def test_it_refuses_them_in_label_names(self):
        self.login(self.alice)
        labels = f"/api/projects/{self.project.pk}/labels/"
        for what, name in DECEPTIVE.items():
            with self.subTest(what):
                r = self.client.post(labels, {"name": name}, format="json")
                self.assertEqual(r.status_code, 400, r.content)
                self.assertIn("U+" if "letters" not in r.json()["detail"] else "letters",
                              r.json()["detail"])
                r = self.client.patch(f"{labels}{self.walk.pk}/", {"name": name}, format="json")
                self.assertEqual(r.status_code, 400, r.content)
        self.assertEqual(sorted(self.project.labels.values_list("name", flat=True)), ["punch", "walk"])

    def test_the_message_names_the_character_and_where(self):
        self.login(self.alice)
        r = self.client.post("/api/projects/", {"name": "Studio\u200bB"}, format="json")
        self.assertIn("character 7 is U+200B (ZERO WIDTH SPACE)", r.json()["detail"])

    def test_names_of_other_scripts_are_welcome(self):
        self.login(self.alice)
        for name in ("\u0421\u0442\u0443\u0434\u0438\u044f MoCap", "\u5c71\u7530 \u30b9\u30bf\u30b8\u30aa",
                     "Bj\u00f6rk's takes", "\u03a7\u03bf\u03c1\u03cc\u03c2 2"):
            with self.subTest(name):
                r = self.client.post("/api/projects/", {"name": name}, format="json")
                self.assertEqual(r.status_code, 201, r.content)
        labels = f"/api/projects/{self.project.pk}/labels/"
        r = self.client.post(labels, {"name": "\u043f\u0440\u044b\u0436\u043e\u043a"}, format="json")
        self.assertEqual(r.status_code, 201, r.content)


class InvitationTextTestCase(BaseTestCase):
    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        cls.dana = get_user_model().objects.create_user("dana", password="dana-password")

    def invitation_seen_by_dana(self, project_name):
        # A name stored before names were held to the rule (or by a path that skips it).
        Project.objects.filter(pk=self.project.pk).update(name=project_name)
        self.login(self.alice)
        r = self.client.post(f"/api/projects/{self.project.pk}/members/",
                             {"username": "dana", "role": "annotator"}, format="json")
        self.assertEqual(r.status_code, 202, r.content)
        self.login(self.dana)
        [invitation] = self.client.get("/api/invitations/").json()
        return invitation

    def test_it_shows_the_project_name_short_and_on_one_line(self):
        phishing = ("Studio A\n\nSECURITY NOTICE: your account will be deleted today. "
                    "Confirm your password at https://cutroom-login.example/verify now " * 2)
        invitation = self.invitation_seen_by_dana(phishing)
        shown = invitation["project"]["name"]
        self.assertLessEqual(len(shown), 60)
        self.assertTrue(shown.startswith("Studio A SECURITY NOTICE"), shown)
        self.assertTrue(shown.endswith("\u2026"), shown)
        self.assertNotIn("\n", shown)

    def test_it_shows_no_invisible_or_direction_characters(self):
        invitation = self.invitation_seen_by_dana("Studio\u202e A\u200b\u2066B")
        self.assertEqual(invitation["project"]["name"], "Studio AB")

    def test_it_shows_only_what_the_inviter_sets(self):
        invitation = self.invitation_seen_by_dana("Studio A")
        self.assertEqual(set(invitation), {"id", "project", "role", "invited_by", "created_at",
                                           "expires_at"})
        self.assertEqual(invitation["project"], {"id": self.project.pk, "name": "Studio A"})
        self.assertEqual(invitation["invited_by"], "alice")
        self.assertEqual(Invitation.objects.get().role, invitation["role"])
