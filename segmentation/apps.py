import os

from django.apps import AppConfig


class SegmentationConfig(AppConfig):
    name = "segmentation"
    verbose_name = "Segmentation"

    def ready(self):
        from django.conf import settings

        # The filesystem broker needs its spool folders before the first message.
        options = getattr(settings, "CELERY_BROKER_TRANSPORT_OPTIONS", {})
        for key in ("data_folder_in", "data_folder_out", "processed_folder"):
            if key in options:
                os.makedirs(options[key], exist_ok=True)
