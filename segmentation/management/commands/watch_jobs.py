import time

from django.conf import settings
from django.core.management.base import BaseCommand, CommandError
from django.db import connection

from segmentation.services import health


class Command(BaseCommand):
    help = (
        "Watch the background jobs from outside the workers, as make up's supervisor does: "
        "every CUTROOM_SWEEP_SECONDS requeue the jobs of processes that died, resend lost "
        "messages and report workers that are stuck (a job queued for CUTROOM_STALL_SECONDS "
        "while a worker process was free). Runs until stopped; --once looks once and exits "
        "with status 1 if the workers are stuck."
    )

    def add_arguments(self, parser):
        parser.add_argument(
            "--concurrency", type=int, default=2,
            help="worker processes in all (workers × their --concurrency); too few only "
                 "reports a stall later, never wrongly",
        )
        parser.add_argument("--once", action="store_true", help="look once, then exit")

    def handle(self, *args, concurrency, once, **options):
        if once:
            stuck = self.report(*health.look(concurrency))
            if stuck:
                raise CommandError(f"the workers are stuck: {stuck}")
            return
        self.stdout.write(f"watching the jobs every {settings.CUTROOM_SWEEP_SECONDS} s")
        while True:
            try:
                self.report(*health.look(concurrency))
            except Exception as exc:  # the database busy or gone: look again next time
                self.stderr.write(f"could not check the jobs ({type(exc).__name__}: {exc})")
            finally:
                connection.close()  # a server restarted meanwhile must not break the next look
            time.sleep(settings.CUTROOM_SWEEP_SECONDS)

    def report(self, swept, stuck):
        if swept:
            self.stdout.write(f"{swept} stale job(s) requeued, failed or resent")
        if stuck:
            self.stderr.write(f"the workers are stuck: {stuck}")
        return stuck
