from django.db import models
from django.utils import timezone


class WorkerHeartbeat(models.Model):
    """A Celery worker's last sign of life, written by its main process every
    ``CUTROOM_HEARTBEAT_SECONDS`` (``segmentation.services.health.beat``): the health
    endpoint tells a running worker from one that is gone by how recent it is."""

    hostname = models.CharField(max_length=255, unique=True)
    queues = models.JSONField(default=list)
    processes = models.PositiveIntegerField(default=0)
    started_at = models.DateTimeField(default=timezone.now)
    seen_at = models.DateTimeField(default=timezone.now)

    def __str__(self):
        return self.hostname
