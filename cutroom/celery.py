"""The Celery app. Workers start with ``celery -A cutroom worker``; its configuration is
the ``CELERY_*`` block of ``cutroom.settings``."""

import os

from celery import Celery

os.environ.setdefault("DJANGO_SETTINGS_MODULE", "cutroom.settings")

app = Celery("cutroom")
app.config_from_object("django.conf:settings", namespace="CELERY")
app.autodiscover_tasks(["segmentation"])


@app.on_after_configure.connect
def make_spool_folders(sender, **kwargs):
    # The filesystem broker (embedded default) needs its folders before the first
    # message, in whichever process (web, worker, `celery inspect`) touches it first.
    options = sender.conf.broker_transport_options or {}
    for key in ("data_folder_in", "data_folder_out", "processed_folder", "control_folder"):
        if key in options:
            os.makedirs(options[key], exist_ok=True)
