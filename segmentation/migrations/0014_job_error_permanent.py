from django.db import migrations, models


class Migration(migrations.Migration):
    dependencies = [
        ("segmentation", "0013_drop_losing_detector_options"),
    ]

    operations = [
        migrations.AddField(
            model_name=model,
            name="error_permanent",
            field=models.BooleanField(default=False),
        )
        for model in ("capture", "detectionrun", "projectcutmodel")
    ]
