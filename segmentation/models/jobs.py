"""Background work shared by captures, detection runs and cut-model trainings: a row
that a worker claims with one conditional UPDATE, renews while it works, and closes with
its result or the error a person can act on."""

from django.conf import settings
from django.db import models
from django.db.models import F, Q
from django.utils import timezone

JOB_STATUSES = (
    ("queued", "Queued"),
    ("processing", "Processing"),
    ("ready", "Ready"),
    ("failed", "Failed"),
)


def claim_cutoff():
    """Claims older than this (not renewed for ``CUTROOM_CLAIM_TIMEOUT`` seconds) belong to
    a process that died."""
    return timezone.now() - timezone.timedelta(seconds=settings.CUTROOM_CLAIM_TIMEOUT)


class ClaimQuerySet(models.QuerySet):
    """Claiming background work with one conditional UPDATE.

    A row can be claimed when it is queued, when the same job message comes back after
    its worker died (same ``claim_token``), or when another claim is older than
    ``CUTROOM_CLAIM_TIMEOUT``. Zero rows updated means another worker has the job.
    """

    def claim(self, pk, token):
        claimable = Q(status="queued") | Q(status="processing") & (
            Q(claim_token=token) | Q(claimed_at__lt=claim_cutoff())
        )
        updated = self.filter(claimable, pk=pk).update(
            status="processing",
            claim_token=token,
            claimed_at=timezone.now(),
            attempts=F("attempts") + 1,
        )
        return updated == 1

    def stale(self):
        """Rows still marked processing whose claim was not renewed within the claim
        timeout: the process running them died."""
        return self.filter(status="processing", claimed_at__lt=claim_cutoff())

    def requeue_failed(self, pk):
        """Put a failed job back in the queue with a fresh attempt count; 0 rows updated
        means it was not failed (a concurrent retry, or nothing to retry). The next try's
        failure decides afresh whether it is permanent."""
        return self.filter(pk=pk, status="failed").update(
            status="queued", error="", error_permanent=False, claim_token="",
            claimed_at=timezone.now(), attempts=0,
        ) == 1

    def waiting_too_long(self, after=None):
        """Queued rows nobody claimed within ``after`` seconds (CUTROOM_RESEND_AFTER): their
        message may be lost (broker down at upload time, queue purged), so they are sent again."""
        after = settings.CUTROOM_RESEND_AFTER if after is None else after
        limit = timezone.now() - timezone.timedelta(seconds=after)
        last_sent = Q(claimed_at__lt=limit) | Q(claimed_at__isnull=True, created_at__lt=limit)
        return self.filter(last_sent, status="queued")


class JSONArrayLength(models.Func):
    """Length of a JSON array column, counted by the database (SQLite and PostgreSQL)."""

    function = "JSON_ARRAY_LENGTH"
    output_field = models.IntegerField()

    def as_postgresql(self, compiler, connection, **extra):
        return self.as_sql(compiler, connection, function="JSONB_ARRAY_LENGTH", **extra)


class Job(models.Model):
    """State shared by every kind of background work (ingest, conversion, detection,
    training): who holds the claim, how often it was claimed, and how it ended.

    A failed job keeps its ``error`` and whether it is ``error_permanent``: the input's
    fault (a bad file, a time limit the same input would reach again), so running it again
    as it is fails the same way; a job that failed for another reason (an internal error,
    workers lost) may succeed if it is retried.

    The ``*_error`` templates are the texts a failed job of this model stores; the job
    runner (``services.jobs``) fills them in.
    """

    status = models.CharField(max_length=20, choices=JOB_STATUSES, default="queued")
    error = models.TextField(blank=True)
    error_permanent = models.BooleanField(default=False)
    claim_token = models.CharField(max_length=64, blank=True)
    # Time of the last claim, or of the last requeue while queued.
    claimed_at = models.DateTimeField(null=True, blank=True)
    attempts = models.PositiveIntegerField(default=0)

    # The task of ``segmentation.tasks`` that does this job (see ``first_job``).
    task = ""
    input_error = "{error}"
    stopped_error = (
        "{what} took too long and was stopped (time limits: ingest with its default "
        "detection {settings.CUTROOM_INGEST_TIME_LIMIT} s, CUTROOM_INGEST_TIME_LIMIT; "
        "detection {settings.CUTROOM_DETECT_TIME_LIMIT} s, CUTROOM_DETECT_TIME_LIMIT). "
        "Try parameters that cost less, or ask the administrators to raise the limit."
    )
    killed_error = (
        "{killed} The same input would run as long again, so it is not retried; try "
        "parameters that cost less, or ask the administrators to raise the limit. The "
        "original upload is kept."
    )
    crashed_error = (
        "{what} failed with an internal error (reference {reference}). The original "
        "upload is kept; report this reference to the service's administrators."
    )
    abandoned_error = (
        "processing started {attempts} times and never finished (the worker was killed "
        "or lost each time); giving up. The original upload is kept."
    )

    class Meta:
        abstract = True

    def first_job(self):
        """The name of the task that starts (or restarts) this job."""
        return self.task

    def queued_behind(self):
        """The queued job that cannot start before this one ends, or None."""
        return None

    def next_in_line(self):
        """The queued job to send once this one ends (it was refused a start while this
        one ran), or None."""
        return self.queued_behind()

    def finish(self, **fields):
        """Store the result, but only if this job's claim still holds."""
        return self._close("ready", "", False, fields)

    def fail(self, error, permanent=False, **fields):
        """Store why the job failed, but only if this job's claim still holds."""
        return self._close("failed", error, permanent, fields)

    def _close(self, status, error, permanent, fields):
        fields.update(status=status, error=error, error_permanent=permanent)
        if any(f.name == "finished_at" for f in self._meta.fields):
            fields.setdefault("finished_at", timezone.now())
        updated = (
            type(self)
            .objects.filter(pk=self.pk, status="processing", claim_token=self.claim_token)
            .update(**fields)
        )
        if updated:
            for name, value in fields.items():
                setattr(self, name, value)
        return updated == 1
