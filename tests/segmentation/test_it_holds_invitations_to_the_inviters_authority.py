"""An invitation carries its inviter's authority, and no more than they still have; one
that was cancelled or has expired says so (issue 48, item 10)."""

from datetime import timedelta

from django.contrib.auth import get_user_model
from django.utils import timezone

from segmentation import services
from segmentation.models import Invitation, Membership
from tests.segmentation.base import BaseTestCase


class InviterAuthorityTestCase(BaseTestCase):
    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        cls.dana = get_user_model().objects.create_user("dana", password="dana-password")
        cls.erin = get_user_model().objects.create_user("erin", password="erin-password")
        services.do_set_member(cls.project, "erin", "admin")

    def invite(self, username="dana", role="admin", by=None):
        self.login(by or self.erin)
        r = self.client.post(f"/api/projects/{self.project.pk}/members/",
                             {"username": username, "role": role}, format="json")
        self.assertEqual(r.status_code, 202, r.content)
        return Invitation.objects.get(username=username, status="pending")

    def accept(self, invitation, user=None):
        self.login(user or self.dana)
        return self.client.post(f"/api/invitations/{invitation.pk}/accept/")

    def test_an_invitation_of_an_admin_since_removed_is_not_accepted(self):
        invitation = self.invite()
        Membership.objects.filter(project=self.project, user=self.erin).delete()
        r = self.accept(invitation)
        self.assertEqual(r.status_code, 403, r.content)
        self.assertIn("erin, who is no longer an admin", r.json()["detail"])
        self.assertIsNone(self.project.role_of(self.dana))

    def test_an_invitation_of_an_admin_since_made_annotator_is_not_accepted(self):
        invitation = self.invite(role="reviewer")
        services.do_set_member(self.project, "erin", "annotator")
        self.assertEqual(self.accept(invitation).status_code, 403)
        self.assertIsNone(self.project.role_of(self.dana))

    def test_an_invitation_of_a_deleted_account_is_not_accepted(self):
        invitation = self.invite()
        self.erin.delete()
        r = self.accept(invitation)
        self.assertEqual(r.status_code, 403, r.content)
        self.assertIsNone(self.project.role_of(self.dana))

    def test_an_invitation_of_an_admin_still_in_office_is_accepted(self):
        invitation = self.invite()
        self.assertEqual(self.accept(invitation).status_code, 200)
        self.assertEqual(self.project.role_of(self.dana), "admin")

    def test_a_cancelled_invitation_says_it_was_cancelled(self):
        invitation = self.invite()
        self.client.delete(f"/api/projects/{self.project.pk}/invitations/{invitation.pk}/")
        for verb in ("accept", "decline"):
            self.login(self.dana)
            r = self.client.post(f"/api/invitations/{invitation.pk}/{verb}/")
            self.assertEqual(r.status_code, 410, r.content)
            self.assertIn("was cancelled", r.json()["detail"])
        self.assertIsNone(self.project.role_of(self.dana))

    def test_an_expired_invitation_says_it_has_expired(self):
        invitation = self.invite()
        Invitation.objects.update(expires_at=timezone.now() - timedelta(seconds=1))
        r = self.accept(invitation)
        self.assertEqual(r.status_code, 410, r.content)
        self.assertIn("has expired", r.json()["detail"])
        self.assertIsNone(self.project.role_of(self.dana))

    def test_someone_elses_invitation_stays_a_404_whatever_its_state(self):
        invitation = self.invite()
        self.client.delete(f"/api/projects/{self.project.pk}/invitations/{invitation.pk}/")
        self.assertEqual(self.accept(invitation, user=self.charlie).status_code, 404)
