"""``manage.py import_captures PATH... --project NAME``: bulk import of capture files."""

from django.contrib.auth import get_user_model
from django.core.management.base import BaseCommand, CommandError

from segmentation.models import Project
from segmentation.services import importing


class Command(BaseCommand):
    help = (
        "Import BVH and CMU ASF/AMC files (and folders of them, recursively) into a project, "
        "as uploads: originals stored unchanged, duplicates recognised, ingest and "
        "detection queued for the worker. Bad files are reported and skipped."
    )

    def add_arguments(self, parser):
        parser.add_argument("paths", nargs="+", metavar="PATH", help="files or folders")
        parser.add_argument("--project", required=True, help="project name (or id)")
        parser.add_argument("--user", help="username recorded as the uploader (a member)")
        parser.add_argument(
            "--asf", help="ASF skeleton for every AMC file (default: found beside each one)"
        )
        parser.add_argument(
            "--no-check", action="store_true",
            help="do not check files before storing them (the worker reports bad ones)",
        )
        parser.add_argument(
            "--full-check", action="store_true",
            help="read every frame of each file before storing it (by default only a BVH's "
                 "hierarchy and header are checked here; the worker reads the frames, and "
                 "fails a capture with a bad one, naming its line)",
        )

    def handle(self, *args, **options):
        project = find_project(options["project"])
        user = find_member(project, options["user"])
        files, outcomes = importing.find_captures(options["paths"])
        progress = Progress(self.stderr, len(files))
        for path in files:
            progress.step(importing.relative(path))
            outcome = importing.import_file(
                project, user, path, asf=options["asf"], check=not options["no_check"],
                full_check=options["full_check"],
            )
            outcomes.append(outcome)
        progress.done()
        self.report(project, outcomes)
        if files and not any(o.status != "failed" for o in outcomes):
            raise CommandError("nothing was imported")

    def report(self, project, outcomes):
        counts = {status: 0 for status in ("imported", "duplicate", "failed")}
        for outcome in outcomes:
            counts[outcome.status] += 1
        for outcome in outcomes:
            if outcome.status == "duplicate":
                self.stdout.write(
                    f"duplicate  {importing.relative(outcome.path)} "
                    f"(already capture {outcome.capture.pk}, {outcome.capture.name!r})"
                )
            elif outcome.status == "failed":
                self.stdout.write(self.style.ERROR(f"failed     {outcome.reason}"))
        self.stdout.write(
            f"{project.name}: {counts['imported']} imported, {counts['duplicate']} duplicate, "
            f"{counts['failed']} failed"
        )
        if counts["imported"]:
            self.stdout.write("Imported captures are queued; a running worker ingests them.")


def find_project(name):
    """The project named ``name`` (or with that id); CommandError lists the choices."""
    matches = list(Project.objects.filter(name=name))
    if not matches and name.isdigit():
        matches = list(Project.objects.filter(pk=int(name)))
    if len(matches) == 1:
        return matches[0]
    if matches:
        ids = ", ".join(str(p.pk) for p in matches)
        raise CommandError(f"--project {name!r}: {len(matches)} projects have that name "
                           f"(ids {ids}); pass the id instead")
    known = ", ".join(repr(p.name) for p in Project.objects.order_by("name")[:20]) or "none"
    raise CommandError(f"--project {name!r}: no such project (projects: {known})")


def find_member(project, username):
    """The user named ``username`` if a member of ``project``; None when not given."""
    if username is None:
        return None
    user = get_user_model().objects.filter(username=username).first()
    if user is None:
        raise CommandError(f"--user {username!r}: no such user")
    if project.role_of(user) is None:
        raise CommandError(f"--user {username!r} is not a member of project {project.name!r}")
    return user


class Progress:
    """A one-line progress bar on a terminal; one line per file otherwise (logs, tests)."""

    WIDTH = 30

    def __init__(self, stream, total):
        self.stream, self.total, self.count = stream, total, 0
        self.tty = stream.isatty()

    def step(self, name):
        self.count += 1
        filled = self.WIDTH * self.count // max(self.total, 1)
        bar = "#" * filled + "." * (self.WIDTH - filled)
        line = f"[{bar}] {self.count}/{self.total} {name}"
        if self.tty:
            self.stream.write(f"\r\033[K{line}", ending="")
            self.stream.flush()
        else:
            self.stream.write(line)

    def done(self):
        if self.tty and self.count:
            self.stream.write("")

