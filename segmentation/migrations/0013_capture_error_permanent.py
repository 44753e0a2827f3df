from django.db import migrations, models


class Migration(migrations.Migration):
    dependencies = [
        ("segmentation", "0012_library_scale"),
    ]

    operations = [
        migrations.AddField(
            model_name="capture",
            name="error_permanent",
            field=models.BooleanField(default=False),
        ),
    ]
