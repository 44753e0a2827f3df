"""The Celery app. Workers start with ``celery -A cutroom worker``; its configuration is
the ``CELERY_*`` block of ``cutroom.settings``."""

import os

from celery import Celery

os.environ.setdefault("DJANGO_SETTINGS_MODULE", "cutroom.settings")

app = Celery("cutroom")
app.config_from_object("django.conf:settings", namespace="CELERY")
app.autodiscover_tasks(["segmentation"])
