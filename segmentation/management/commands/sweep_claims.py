from django.core.management.base import BaseCommand

from segmentation.services import sweep_stale_claims


class Command(BaseCommand):
    help = (
        "Requeue captures and runs left in 'processing' by a worker that vanished "
        "(claim older than CUTROOM_CLAIM_TIMEOUT); fail those retried too often."
    )

    def handle(self, *args, **options):
        count = sweep_stale_claims()
        self.stdout.write(f"{count} stale job(s) requeued or failed")
