"""``UsernameKey`` and ``ThrottleLock`` are now the accounts app's (``accounts`` 0002):
only this app's record of them goes; their tables and rows stay."""

from django.db import migrations


class Migration(migrations.Migration):

    dependencies = [
        ("segmentation", "0022_library_list_postgres_label_runs"),
        ("accounts", "0002_username_keys_and_throttle_locks"),
    ]

    operations = [
        migrations.SeparateDatabaseAndState(state_operations=[
            migrations.DeleteModel(name="ThrottleLock"),
            migrations.DeleteModel(name="UsernameKey"),
        ]),
    ]
