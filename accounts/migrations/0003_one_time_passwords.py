import django.db.models.deletion
import django.utils.timezone
from django.conf import settings
from django.db import migrations, models


class Migration(migrations.Migration):

    dependencies = [
        migrations.swappable_dependency(settings.AUTH_USER_MODEL),
        ("accounts", "0002_username_keys_and_throttle_locks"),
    ]

    operations = [
        migrations.CreateModel(
            name="OneTimePassword",
            fields=[
                ("user", models.OneToOneField(on_delete=django.db.models.deletion.CASCADE, primary_key=True, related_name="one_time_password", serialize=False, to=settings.AUTH_USER_MODEL)),
                ("issued_at", models.DateTimeField(default=django.utils.timezone.now)),
            ],
        ),
    ]
