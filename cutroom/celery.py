"""The Celery app. Workers start with ``celery -A cutroom worker``; its configuration is
the ``CELERY_*`` block of ``cutroom.settings``."""

import os

from celery import Celery
from kombu.transport import TRANSPORT_ALIASES

os.environ.setdefault("DJANGO_SETTINGS_MODULE", "cutroom.settings")

# ``sqlite://`` (the embedded default) is the SQLite-file broker of cutroom.broker.
TRANSPORT_ALIASES.setdefault("sqlite", "cutroom.broker:Transport")

app = Celery("cutroom")
app.config_from_object("django.conf:settings", namespace="CELERY")
app.autodiscover_tasks(["segmentation"])
