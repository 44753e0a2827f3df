"""Usernames: every spelling of a name (spaces around it, case, compatibility forms) is
one account, and names with invisible or look-alike characters cannot be created."""

import io
from unittest import mock

from django.contrib.auth import get_user_model
from django.core.management import CommandError, call_command
from django.db import IntegrityError, transaction
from django.test import Client, SimpleTestCase

from accounts import usernames
from tests.segmentation.base import BaseTestCase


class KeyTestCase(SimpleTestCase):
    def test_spaces_case_and_compatibility_forms_share_one_key(self):
        for spelling in (" bob", "bob\t", "BOB", "\uff42\uff4f\uff42", "\u24b7ob", "\u3000bob"):
            self.assertEqual(usernames.key(spelling), "bob", repr(spelling))

    def test_case_folding_is_full_not_just_lower_case(self):
        self.assertEqual(usernames.key("STRASSE"), usernames.key("stra\u00dfe"))


class CleanTestCase(SimpleTestCase):
    def refused(self, name):
        with self.assertRaises(usernames.UsernameError) as caught:
            usernames.clean(name)
        return str(caught.exception)

    def test_it_stores_the_name_stripped_and_in_nfkc_keeping_its_case(self):
        self.assertEqual(usernames.clean("  \uff25rin "), "Erin")

    def test_it_refuses_zero_width_and_other_format_characters_naming_them(self):
        self.assertIn("character 2 is U+200B (ZERO WIDTH SPACE)", self.refused("b\u200bob"))
        for char in ("\u200d", "\u2060", "\u202e", "\ufeff", "\u00ad"):
            self.refused(f"bo{char}b")

    def test_it_refuses_spaces_other_than_the_plain_one_and_control_characters(self):
        self.assertIn("U+00A0", self.refused("bob\u00a0smith"))
        self.refused("bob\u2028x")
        self.refused("bob\x07")
        self.assertEqual(usernames.clean("bob smith"), "bob smith")

    def test_it_refuses_latin_mixed_with_cyrillic_or_greek_look_alikes(self):
        self.assertIn("Cyrillic and Latin", self.refused("p\u0430ypal"))
        self.refused("b\u03bfb")  # Greek omicron
        self.assertEqual(usernames.clean("\u0431\u043e\u0431"), "\u0431\u043e\u0431")
        self.assertEqual(usernames.clean("\u5c71\u7530-yamada"), "\u5c71\u7530-yamada")

    def test_it_refuses_a_name_of_cyrillic_or_greek_letters_that_all_look_latin(self):
        self.assertIn("Cyrillic letters that all look like Latin", self.refused("\u0430\u0441\u0435"))
        self.refused("\u0421\u0410\u0420-1")  # "CAP-1"
        self.refused("\u03bf\u03ba")  # Greek "ok"
        self.assertEqual(usernames.clean("\u0421\u0435\u0440\u0433\u0435\u0439"),
                         "\u0421\u0435\u0440\u0433\u0435\u0439")  # Сергей

    def test_it_refuses_empty_and_overlong_names(self):
        self.refused("   ")
        self.refused("x" * 151)


class SignInTestCase(BaseTestCase):
    def test_any_spelling_of_the_name_signs_in(self):
        for spelling in (" bob ", "BOB", "\uff42\uff4f\uff42"):
            r = self.client.post("/api/auth/token/", {"username": spelling, "password": "bob-password"},
                                 format="json")
            self.assertEqual(r.status_code, 200, spelling)


class CreationTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.alice.is_superuser = True
        self.alice.save()

    def create(self, username):
        self.login(self.alice)
        url = f"/api/projects/{self.project.pk}/members/new-account/"
        return self.client.post(url, {"username": username, "role": "annotator"}, format="json")

    def test_a_site_admin_cannot_create_a_zero_width_look_alike(self):
        r = self.create("bo\u200bb")
        self.assertEqual(r.status_code, 400)
        self.assertIn("username: character 3 is U+200B", r.json()["detail"])
        self.assertEqual(get_user_model().objects.filter(username__startswith="bo").count(), 1)

    def test_a_site_admin_cannot_create_another_case_or_form_of_a_name(self):
        for spelling in ("Bob", "\uff42\uff4f\uff42"):
            r = self.create(spelling)
            self.assertEqual(r.status_code, 400, spelling)
            self.assertIn("an account named 'bob' already exists", r.json()["detail"])

    def test_the_admins_user_forms_refuse_look_alikes(self):
        admin = Client()
        admin.force_login(self.alice)
        self.alice.is_staff = True
        self.alice.save()
        admin.force_login(self.alice)
        data = {"password1": "a-long-unusual-pass", "password2": "a-long-unusual-pass",
                "usable_password": "true"}
        r = admin.post("/admin/auth/user/add/", {**data, "username": "bob\u2060"})
        self.assertContains(r, "U+2060")
        r = admin.post("/admin/auth/user/add/", {**data, "username": "\uff22ob"})
        self.assertContains(r, "already exists")
        r = admin.post("/admin/auth/user/add/", {**data, "username": "  erin "})
        self.assertEqual(r.status_code, 302)
        self.assertTrue(get_user_model().objects.filter(username="erin").exists())
        erin = get_user_model().objects.get(username="erin")
        r = admin.post(f"/admin/auth/user/{erin.pk}/change/", {
            "username": "eri\u200dn", "date_joined_0": "2026-01-01", "date_joined_1": "00:00:00",
        })
        self.assertContains(r, "U+200D")


class AnyWayOfCreatingTestCase(BaseTestCase):
    def test_an_account_made_by_a_command_or_script_is_checked_too(self):
        users = get_user_model().objects
        for name in ("bo\u200bb", "BOB", "p\u0430ypal"):
            with self.assertRaises(usernames.UsernameError):
                users.create_superuser(name, password="x")
        self.assertEqual(users.create_user("  dora ").username, "dora")

    def test_renaming_is_left_to_the_forms_and_saving_an_account_again_is_not_refused(self):
        self.bob.first_name = "Bob"
        self.bob.save()


class KeyedSignInTestCase(BaseTestCase):
    """Sign-in finds an account by its stored key, so other cases of any script sign in on
    every database (SQLite's own case-insensitive match knows only ASCII)."""

    def sign_in(self, username, password):
        return self.client.post("/api/auth/token/", {"username": username, "password": password},
                                format="json")

    def test_a_greek_name_typed_in_capitals_signs_in(self):
        get_user_model().objects.create_user("\u0395\u03bb\u03ad\u03bd\u03b7", password="p-Elena-9")
        for spelling in ("\u0395\u039b\u0388\u039d\u0397", "\u03b5\u03bb\u03ad\u03bd\u03b7 "):
            self.assertEqual(self.sign_in(spelling, "p-Elena-9").status_code, 200, spelling)

    def test_a_cyrillic_name_typed_in_another_case_is_the_same_account_for_creation(self):
        get_user_model().objects.create_user("\u0421\u0435\u0440\u0433\u0435\u0439", password="x")
        with self.assertRaises(usernames.UsernameError):
            get_user_model().objects.create_user("\u0421\u0415\u0420\u0413\u0415\u0419", password="x")

    def test_the_database_refuses_a_second_account_of_one_key_made_at_the_same_moment(self):
        # Both creations passed the check before either was saved: the unique key decides.
        users = get_user_model().objects
        users.create_user("dora", password="x")
        with mock.patch.object(usernames, "check_available"):
            with self.assertRaises(IntegrityError), transaction.atomic():
                users.create_user("DORA", password="x")
        self.assertEqual(list(users.filter(username__iexact="dora").values_list("username", flat=True)),
                         ["dora"])

    def test_a_rename_follows_the_key_and_a_clashing_rename_keeps_none(self):
        self.assertEqual(usernames.find_user("BOB"), self.bob)
        self.bob.username = "robert"
        self.bob.save()
        self.assertEqual(usernames.find_user("ROBERT"), self.bob)
        self.assertIsNone(usernames.find_user("BOB"))
        self.bob.username = "Alice"  # an admin's rename into a clash with alice
        self.bob.save()
        self.assertEqual(usernames.find_user("alice"), self.alice)
        self.assertEqual(usernames.find_user("Alice"), self.bob)  # its exact name only


class CheckUsernamesCommandTestCase(BaseTestCase):
    def run_command(self):
        out = io.StringIO()
        try:
            call_command("check_usernames", stdout=out)
        except CommandError as exc:
            return out.getvalue(), str(exc)
        return out.getvalue(), None

    def test_it_says_all_is_well_when_it_is(self):
        out, error = self.run_command()
        self.assertIsNone(error)
        self.assertIn("every username follows the rules", out)

    def test_it_lists_accounts_made_before_the_rules(self):
        users = get_user_model().objects
        # Rows written past the rules, as an older release could leave them.
        with mock.patch.object(usernames, "clean", side_effect=lambda name: name), \
                mock.patch.object(usernames, "check_available"):
            lookalike = users.create_user("p\u0430ypal", password="x")
        twin = users.create_user("twin", password="x")
        twin.username = "BOB"
        twin.save()
        out, error = self.run_command()
        self.assertEqual(error, "2 account(s) to rename")
        self.assertIn(f"account {lookalike.pk} 'p\u0430ypal': mixes letters of the Cyrillic and Latin", out)
        self.assertIn(f"account {twin.pk} 'BOB': differs only in case or form from account "
                      f"{self.bob.pk} 'bob'", out)
