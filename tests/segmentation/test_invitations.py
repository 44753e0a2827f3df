"""Adding someone to a project invites them: nobody learns from it whether an account
exists (unless they are a site admin), and nobody joins a project they did not accept."""

from datetime import timedelta

from django.contrib.auth import get_user_model
from django.test import override_settings
from django.utils import timezone

from segmentation import services
from segmentation.models import Invitation
from tests.segmentation.base import BaseTestCase


class InvitationsTestCase(BaseTestCase):
    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        cls.dana = get_user_model().objects.create_user("dana", password="dana-password")
        cls.root = get_user_model().objects.create_superuser("root", password="root-password")

    def add(self, username, role="annotator", by=None, project=None):
        self.login(by or self.alice)
        url = f"/api/projects/{(project or self.project).pk}/members/"
        return self.client.post(url, {"username": username, "role": role}, format="json")

    def invitations_of(self, user):
        self.login(user)
        return self.client.get("/api/invitations/").json()

    def answer(self, user, invitation_id, verb):
        self.login(user)
        return self.client.post(f"/api/invitations/{invitation_id}/{verb}/")

    def comparable(self, response, username):
        """The answer with what must differ between two invitations taken out."""
        body = response.json()
        invitation = {k: v for k, v in body["invitation"].items()
                      if k not in ("id", "username", "created_at", "expires_at")}
        return response.status_code, body["detail"].replace(username, "<name>"), invitation

    # A project admin (who is no site admin) learns nothing about accounts.

    def test_a_project_admin_gets_the_same_answer_whether_or_not_the_account_exists(self):
        existing, missing = self.add("dana"), self.add("nobody-has-this-name")
        self.assertEqual(existing.status_code, 202)
        self.assertEqual(self.comparable(existing, "dana"),
                         self.comparable(missing, "nobody-has-this-name"))

    def test_a_project_admin_sees_the_same_pending_list_whether_or_not_the_account_exists(self):
        self.add("dana", "reviewer")
        self.add("nobody-has-this-name", "reviewer")
        listed = self.client.get(f"/api/projects/{self.project.pk}/invitations/").json()
        self.assertEqual([(i["username"], i["role"], i["invited_by"]) for i in listed],
                         [("dana", "reviewer", "alice"), ("nobody-has-this-name", "reviewer", "alice")])

    def test_a_project_admin_cannot_place_anyone_in_the_project(self):
        self.add("dana", "admin")
        self.assertIsNone(self.project.role_of(self.dana))
        self.login(self.dana)
        self.assertEqual(self.client.get("/api/projects/").json(), [])
        self.assertEqual(self.client.get(f"/api/projects/{self.project.pk}/").status_code, 404)

    # The roles that may not invite at all.

    def test_an_outsider_cannot_invite_into_a_project_they_do_not_see(self):
        self.assertEqual(self.add("dana", by=self.charlie).status_code, 404)
        self.assertFalse(Invitation.objects.exists())

    def test_an_annotator_cannot_invite(self):
        self.assertEqual(self.add("dana", by=self.bob).status_code, 403)
        self.assertFalse(Invitation.objects.exists())

    def test_a_reviewer_cannot_invite(self):
        self.assertEqual(self.add("dana", by=self.rachel).status_code, 403)
        self.assertFalse(Invitation.objects.exists())

    def test_only_admins_see_a_projects_pending_invitations(self):
        self.add("dana")
        for user, status in ((self.bob, 403), (self.rachel, 403), (self.charlie, 404)):
            self.login(user)
            r = self.client.get(f"/api/projects/{self.project.pk}/invitations/")
            self.assertEqual(r.status_code, status, user)

    # A site admin may learn whether an account exists, but places nobody either.

    def test_a_site_admin_is_told_that_no_account_has_the_name(self):
        self.add("root", "admin")  # alice invites root, who accepts
        self.answer(self.root, Invitation.objects.get(username="root").pk, "accept")
        r = self.add("nobody-has-this-name", by=self.root)
        self.assertEqual(r.status_code, 400)
        self.assertIn("no user named 'nobody-has-this-name'", r.json()["detail"])
        self.assertFalse(Invitation.objects.filter(username="nobody-has-this-name").exists())

    def test_the_caller_learns_whether_their_invitations_say_that_no_account_has_a_name(self):
        """The Team page tells a site admin that a name no account has is refused, and a
        project admin that the answer is the same either way: both read it from /api/me/."""
        for user, sees in ((self.root, True), (self.alice, False)):
            self.login(user)
            self.assertIs(self.client.get("/api/me/").json()["can_see_accounts"], sees, user)

    def test_a_site_admin_cannot_place_anyone_in_the_project_either(self):
        self.add("root", "admin")
        self.answer(self.root, Invitation.objects.get(username="root").pk, "accept")
        self.assertEqual(self.add("dana", by=self.root).status_code, 202)
        self.assertIsNone(self.project.role_of(self.dana))

    def test_a_site_admin_who_is_no_member_cannot_invite_through_the_api(self):
        self.assertEqual(self.add("dana", by=self.root).status_code, 404)
        self.assertFalse(Invitation.objects.exists())

    # The invitee sees, accepts or declines; nobody else can answer for them.

    def test_the_invitee_sees_the_invitation_and_joins_by_accepting_it(self):
        self.add("dana", "reviewer")
        [invitation] = self.invitations_of(self.dana)
        self.assertEqual((invitation["project"]["name"], invitation["role"], invitation["invited_by"]),
                         ("Studio A", "reviewer", "alice"))
        r = self.answer(self.dana, invitation["id"], "accept")
        self.assertEqual((r.status_code, r.json()["role"]), (200, "reviewer"))
        self.assertEqual(self.project.role_of(self.dana), "reviewer")
        self.assertEqual(self.invitations_of(self.dana), [])

    def test_an_accepted_invitation_stays_on_record_with_who_invited_and_who_accepted(self):
        self.add("dana")
        invitation = Invitation.objects.get()
        self.answer(self.dana, invitation.pk, "accept")
        invitation.refresh_from_db()
        self.assertEqual((invitation.status, invitation.invited_by, invitation.answered_by),
                         ("accepted", self.alice, self.dana))
        self.assertLess(timezone.now() - invitation.answered_at, timedelta(minutes=1))

    def test_declining_keeps_the_invitee_out(self):
        self.add("dana")
        invitation = Invitation.objects.get()
        self.assertEqual(self.answer(self.dana, invitation.pk, "decline").status_code, 200)
        self.assertIsNone(self.project.role_of(self.dana))
        self.assertEqual(Invitation.objects.get().status, "declined")
        self.assertEqual(self.answer(self.dana, invitation.pk, "accept").status_code, 404)

    def test_nobody_else_can_accept_someone_elses_invitation(self):
        self.add("dana", "admin")
        invitation = Invitation.objects.get()
        for user in (self.charlie, self.bob, self.alice, self.root):
            self.assertEqual(self.answer(user, invitation.pk, "accept").status_code, 404, user)
        self.assertEqual(self.invitations_of(self.charlie), [])
        self.assertIsNone(self.project.role_of(self.dana))

    def test_an_expired_invitation_cannot_be_accepted(self):
        self.add("dana")
        Invitation.objects.update(expires_at=timezone.now() - timedelta(seconds=1))
        self.assertEqual(self.invitations_of(self.dana), [])
        self.assertEqual(self.answer(self.dana, Invitation.objects.get().pk, "accept").status_code, 404)

    def test_an_admin_cancels_a_pending_invitation(self):
        self.add("dana")
        invitation = Invitation.objects.get()
        r = self.client.delete(f"/api/projects/{self.project.pk}/invitations/{invitation.pk}/")
        self.assertEqual(r.status_code, 204)
        self.assertEqual(self.answer(self.dana, invitation.pk, "accept").status_code, 404)
        self.assertEqual(Invitation.objects.get().status, "cancelled")

    def test_inviting_a_name_again_replaces_its_pending_invitation(self):
        self.add("dana", "annotator")
        self.add("dana", "reviewer")
        self.assertEqual([i["role"] for i in self.invitations_of(self.dana)], ["reviewer"])

    def test_an_overlong_username_is_refused_with_its_length(self):
        r = self.add("x" * 151)
        self.assertEqual(r.status_code, 400)
        self.assertIn("1 to 150 characters, got 151", r.json()["detail"])


class InvitationRateTestCase(BaseTestCase):
    """Nobody can flood a person's list of invitations: each inviter sends at most
    CUTROOM_INVITATIONS_PER_HOUR, each username receives at most
    CUTROOM_INVITATIONS_PER_INVITEE a day, from everyone together."""

    def add(self, username, by, project):
        self.login(by)
        return self.client.post(f"/api/projects/{project.pk}/members/",
                                {"username": username, "role": "annotator"}, format="json")

    def projects_of(self, user, n):
        return [services.do_create_project(user, f"{user.username} studio {i}") for i in range(n)]

    @override_settings(CUTROOM_INVITATIONS_PER_HOUR=3, CUTROOM_INVITATIONS_PER_INVITEE=0)
    def test_an_inviter_is_refused_past_the_hourly_limit(self):
        codes = [self.add(f"person{i}", self.charlie, self.other_project).status_code for i in range(4)]
        self.assertEqual(codes, [202, 202, 202, 429])
        r = self.add("person9", self.charlie, self.other_project)
        self.assertIn("the limit is 3 per hour (CUTROOM_INVITATIONS_PER_HOUR)", r.json()["detail"])
        self.assertGreater(int(r["Retry-After"]), 3500)
        self.assertEqual(self.add("person9", self.alice, self.project).status_code, 202)

    @override_settings(CUTROOM_INVITATIONS_PER_HOUR=0, CUTROOM_INVITATIONS_PER_INVITEE=2)
    def test_a_username_receives_at_most_its_daily_limit_from_everyone(self):
        charlies = self.projects_of(self.charlie, 2)
        codes = [self.add("bob", self.charlie, p).status_code for p in charlies]
        codes.append(self.add("bob", self.charlie, self.other_project).status_code)
        self.assertEqual(codes, [202, 202, 429])
        self.assertIn("(CUTROOM_INVITATIONS_PER_INVITEE)",
                      self.add("bob", self.charlie, self.other_project).json()["detail"])
        self.login(self.bob)
        self.assertEqual(len(self.client.get("/api/invitations/").json()), 2)

    @override_settings(CUTROOM_INVITATIONS_PER_HOUR=0, CUTROOM_INVITATIONS_PER_INVITEE=2)
    def test_the_invitee_limit_reads_the_same_for_a_name_without_account(self):
        charlies = self.projects_of(self.charlie, 3)
        for name in ("bob", "nobody-has-this"):
            for p in charlies[:2]:
                self.add(name, self.charlie, p)
        one = self.add("bob", self.charlie, charlies[2])
        other = self.add("nobody-has-this", self.charlie, charlies[2])
        self.assertEqual((one.status_code, other.status_code), (429, 429))
        self.assertEqual(one.json()["detail"].replace("'bob'", "<name>"),
                         other.json()["detail"].replace("'nobody-has-this'", "<name>"))

    @override_settings(CUTROOM_INVITATIONS_PER_HOUR=0, CUTROOM_INVITATIONS_PER_INVITEE=1)
    def test_inviting_the_same_username_again_to_one_project_replaces_and_is_not_refused(self):
        self.assertEqual(self.add("bob", self.charlie, self.other_project).status_code, 202)
        self.assertEqual(self.add("bob", self.charlie, self.other_project).status_code, 202)

    @override_settings(CUTROOM_INVITATIONS_PER_HOUR=0, CUTROOM_INVITATIONS_PER_INVITEE=1)
    def test_spellings_of_a_name_count_as_that_name_and_reach_its_account(self):
        charlies = self.projects_of(self.charlie, 2)
        self.assertEqual(self.add(" \uff42ob ", self.charlie, charlies[0]).status_code, 202)
        self.assertEqual(self.add("bob", self.charlie, charlies[1]).status_code, 429)
        self.login(self.bob)
        self.assertEqual(len(self.client.get("/api/invitations/").json()), 1)
