from django.core.management.base import BaseCommand, CommandError

from segmentation.services.backup import BackupError, do_restore


class Command(BaseCommand):
    help = ("Restore a backup made by `manage.py backup` into this installation, which must be "
            "empty (a new database, empty MEDIA_ROOT and SIMILAR_INDEX_DIR).")

    def add_arguments(self, parser):
        parser.add_argument("path", help="the backup file")

    def handle(self, *args, **options):
        try:
            manifest = do_restore(options["path"])
        except BackupError as exc:
            raise CommandError(str(exc)) from None
        self.stdout.write(f"restored {options['path']} (made {manifest['created']} on "
                          f"{manifest['database']})")
