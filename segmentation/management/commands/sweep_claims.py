from django.conf import settings
from django.core.management.base import BaseCommand
from kombu.transport import resolve_transport

from segmentation.services import jobs


class Command(BaseCommand):
    help = (
        "Requeue captures, runs and cut-model trainings left in 'processing' by a worker that vanished "
        "(claim older than CUTROOM_CLAIM_TIMEOUT); fail those retried too often."
    )

    def add_arguments(self, parser):
        parser.add_argument(
            "--release-broker", action="store_true",
            help="also hand out again every message the SQLite broker has reserved "
                 "(only when no worker is running)",
        )

    def handle(self, *args, **options):
        count = jobs.sweep()
        released = ""
        if options["release_broker"] and settings.CELERY_BROKER_URL.startswith("sqlite"):
            # The transport the broker URL names (the project registers it with kombu).
            transport = resolve_transport("sqlite")
            path = settings.CELERY_BROKER_TRANSPORT_OPTIONS["path"]
            released = f"; {transport.release_all(path)} broker message(s) released"
        self.stdout.write(f"{count} stale job(s) requeued or failed{released}")
