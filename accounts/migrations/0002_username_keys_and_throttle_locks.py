"""The key of each username and the throttle's row locks join the accounts app.

Only Django's record of the models moves (``SeparateDatabaseAndState``): the tables keep
their names (``segmentation_usernamekey``, ``segmentation_throttlelock``) and their rows,
and ``segmentation`` 0023 drops the models from its own record. The content types follow,
so that permissions granted on them still hold.
"""

import django.db.models.deletion
import django.utils.timezone
from django.conf import settings
from django.db import migrations, models

MOVED = ("usernamekey", "throttlelock")


def move_content_types(source, target):
    def move(apps, schema_editor):
        content_types = apps.get_model("contenttypes", "ContentType").objects.using(
            schema_editor.connection.alias)
        there = set(content_types.filter(app_label=target, model__in=MOVED)
                    .values_list("model", flat=True))
        content_types.filter(app_label=source, model__in=set(MOVED) - there).update(app_label=target)
    return move


class Migration(migrations.Migration):

    dependencies = [
        migrations.swappable_dependency(settings.AUTH_USER_MODEL),
        ("contenttypes", "0002_remove_content_type_name"),
        ("accounts", "0001_api_tokens_and_login_failures"),
        ("segmentation", "0022_library_list_postgres_label_runs"),
    ]

    operations = [
        migrations.SeparateDatabaseAndState(state_operations=[
            migrations.CreateModel(
                name="ThrottleLock",
                fields=[
                    ("id", models.BigAutoField(auto_created=True, primary_key=True, serialize=False,
                                               verbose_name="ID")),
                    ("key", models.CharField(max_length=64, unique=True)),
                    ("used_at", models.DateTimeField(db_index=True, default=django.utils.timezone.now)),
                ],
                options={"db_table": "segmentation_throttlelock"},
            ),
            migrations.CreateModel(
                name="UsernameKey",
                fields=[
                    ("user", models.OneToOneField(
                        on_delete=django.db.models.deletion.CASCADE, primary_key=True,
                        related_name="username_key", serialize=False,
                        to=settings.AUTH_USER_MODEL)),
                    ("digest", models.CharField(max_length=64, null=True, unique=True)),
                ],
                options={"db_table": "segmentation_usernamekey"},
            ),
        ]),
        migrations.RunPython(move_content_types("segmentation", "accounts"),
                             move_content_types("accounts", "segmentation")),
    ]
