"""Every account gets the key of its username (``UsernameKey``): the oldest account of a
key holds it; a later one that shares it (made before the rules) keeps none and signs in
by its exact name only, and ``manage.py check_usernames`` lists it."""

import hashlib
import unicodedata

import django.db.models.deletion
from django.conf import settings
from django.db import migrations, models


def key_digest(name):
    # usernames.digest as it is at this migration.
    name = unicodedata.normalize("NFKC", name.strip())
    key = unicodedata.normalize("NFKC", name.casefold()).strip()
    return hashlib.sha256(key.encode("utf-8", "surrogatepass")).hexdigest()


def store_keys(apps, schema_editor):
    User = apps.get_model(*settings.AUTH_USER_MODEL.split("."))
    UsernameKey = apps.get_model("segmentation", "UsernameKey")
    taken = set()
    rows = []
    for pk, username in User.objects.order_by("pk").values_list("pk", "username").iterator():
        digest = key_digest(username)
        rows.append(UsernameKey(user_id=pk, digest=None if digest in taken else digest))
        taken.add(digest)
    UsernameKey.objects.bulk_create(rows, batch_size=1000)


class Migration(migrations.Migration):

    dependencies = [
        migrations.swappable_dependency(settings.AUTH_USER_MODEL),
        ("segmentation", "0017_auth_limits"),
    ]

    operations = [
        migrations.CreateModel(
            name="UsernameKey",
            fields=[
                ("user", models.OneToOneField(
                    on_delete=django.db.models.deletion.CASCADE, primary_key=True,
                    related_name="username_key", serialize=False,
                    to=settings.AUTH_USER_MODEL)),
                ("digest", models.CharField(max_length=64, null=True, unique=True)),
            ],
        ),
        migrations.RunPython(store_keys, migrations.RunPython.noop),
    ]
