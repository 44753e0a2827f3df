"""Migration 0018 stores the key of every existing account's username; of accounts made
before the rules whose names differ only in case or form, the oldest holds the key."""

from tests.segmentation.migrations import MigrationTestCase

BEFORE = [("segmentation", "0017_auth_limits")]
AFTER = [("segmentation", "0018_username_keys")]


class UsernameKeyMigrationTest(MigrationTestCase):
    def setUp(self):
        apps = self.migrate(BEFORE)
        users = apps.get_model("auth", "User").objects
        self.bob = users.create(username="bob")
        self.big_bob = users.create(username="BOB")
        self.elena = users.create(username="\u0395\u03bb\u03ad\u03bd\u03b7")
        self.apps = self.migrate(AFTER)

    def test_every_account_gets_a_row_and_the_oldest_of_a_key_holds_it(self):
        from accounts import usernames

        keys = dict(self.apps.get_model("segmentation", "UsernameKey").objects
                    .values_list("user_id", "digest"))
        assert keys == {self.bob.pk: usernames.digest("bob"), self.big_bob.pk: None,
                        self.elena.pk: usernames.digest("\u0395\u039b\u0388\u039d\u0397")}
