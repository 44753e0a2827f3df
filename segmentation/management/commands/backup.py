from pathlib import Path

from django.conf import settings
from django.core.management.base import BaseCommand, CommandError
from django.utils import timezone

from segmentation.services.backup import do_backup


class Command(BaseCommand):
    help = ("Write a backup of this installation (database rows, stored originals and derived "
            "files, cut models, similar-clip indexes) to one tar file; `manage.py restore` "
            "puts it back into an empty installation.")

    def add_arguments(self, parser):
        parser.add_argument("path", nargs="?", help="the file to write (default: "
                            "var/backups/cutroom-<UTC time>.tar)")

    def handle(self, *args, **options):
        path = options["path"] or (Path(settings.VAR_DIR) / "backups" /
                                   f"cutroom-{timezone.now():%Y%m%d-%H%M%S}.tar")
        try:
            manifest = do_backup(path)
        except OSError as exc:
            raise CommandError(f"{path}: cannot write the backup ({exc.strerror or exc})") from None
        self.stdout.write(f"backup written to {path} ({len(manifest['migrations'])} "
                          f"migrations, {manifest['database']})")
