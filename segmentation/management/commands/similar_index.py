from django.core.management.base import BaseCommand, CommandError

from segmentation.models import Project
from segmentation.similar import updates


class Command(BaseCommand):
    help = (
        "Bring the similar-clip vector indexes in step with the library (remove deleted "
        "segments, add new ones), or rebuild them from scratch with --rebuild."
    )

    def add_arguments(self, parser):
        parser.add_argument("--project", type=int, action="append",
                            help="project id (repeatable); default: every project")
        parser.add_argument("--rebuild", action="store_true",
                            help="write each index from scratch instead of updating it")

    def handle(self, *args, project=None, rebuild=False, **options):
        ids = project or list(Project.objects.order_by("id").values_list("id", flat=True))
        unknown = set(ids) - set(Project.objects.filter(pk__in=ids).values_list("id", flat=True))
        if unknown:
            raise CommandError(f"--project: no project with id {', '.join(map(str, sorted(unknown)))}")
        for pk in ids:
            manifest = updates.build(pk) if rebuild else updates.update(pk)
            if manifest is None:
                self.stdout.write(f"project {pk}: no described segments, no index")
            else:
                self.stdout.write(f"project {pk}: {manifest['count']} segments indexed "
                                  f"({manifest['bytes'] / 1e6:.1f} MB, {manifest['file']})")
