from django.core.management.base import BaseCommand

from segmentation.services import sweep_stale_claims
from segmentation.services.adaptation import sweep_stale_trainings


class Command(BaseCommand):
    help = (
        "Requeue captures, runs and cut-model trainings left in 'processing' by a worker that vanished "
        "(claim older than CUTROOM_CLAIM_TIMEOUT); fail those retried too often."
    )

    def handle(self, *args, **options):
        count = sweep_stale_claims() + sweep_stale_trainings()
        self.stdout.write(f"{count} stale job(s) requeued or failed")
