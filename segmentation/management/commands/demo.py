"""``manage.py demo``: a demo project with users, labels and takes, safe to run again.

Demo data is added once: the project's members and labels are set when the project is created,
and a later run leaves them as the project's admins keep them (a renamed or removed label, a
changed role stay so). Takes not yet uploaded are added on every run (one placed under
``../shared/data`` later, say); uploads are recognised by checksum, so none comes twice.
"""

import io
from pathlib import Path

from django.contrib.auth import get_user_model
from django.core.files.base import ContentFile
from django.core.management.base import BaseCommand
from django.db import transaction

from motionlib import synth, write_bvh
from motionlib.shared_data import data_dir
from segmentation import services
from segmentation.models import Project
from segmentation.services import importing

PROJECT = "Demo studio"
PASSWORD = "cutroom-demo"
# username -> (role in the demo project, Django superuser?)
USERS = {"admin": ("admin", True), "annotator": ("annotator", False), "reviewer": ("reviewer", False)}
# (name, colour, hotkey): the synthetic actions, the CMU exercise classes, and common extras.
LABELS = [
    ("walk", "#2563eb", "1"), ("run", "#16a34a", "2"), ("jump", "#f59e0b", "3"),
    ("squat", "#9333ea", "4"), ("punch", "#dc2626", "5"), ("kick", "#ea580c", "6"),
    ("jumping jack", "#0891b2", "7"), ("arm circles", "#db2777", "8"), ("idle", "#6b7280", "9"),
    ("knee raise", "#65a30d", None), ("twist", "#0d9488", None),
    ("side reach", "#7c3aed", None), ("side bend", "#c026d3", None),
    ("toe touch", "#b45309", None), ("turn", "#475569", None),
]
# (seed, seconds) of the generated takes: different lengths and action orders.
SYNTH_TAKES = [(1, 40.0), (2, 75.0), (3, 120.0)]
# Real CMU takes beside the repository, relative to shared/data: (capture, asf or None).
CMU_TAKES = [
    ("cmu/bvh/13_29.bvh", None),
    ("cmu/amc/13_30.amc", "cmu/asf/13.asf"),
    ("cmu/amc/86_01.amc", "cmu/asf/86.asf"),
]


class Command(BaseCommand):
    help = (
        "Create the demo project (labels, an annotator and a reviewer) and add generated "
        "takes plus the CMU takes under ../shared/data when present, as uploads that a "
        "worker ingests. Running it again adds nothing twice."
    )

    def add_arguments(self, parser):
        parser.add_argument(
            "--shared-data", type=Path, default=None,
            help="folder with cmu/bvh, cmu/amc, cmu/asf (default: ../shared/data)",
        )
        parser.add_argument(
            "--no-shared-data", action="store_true", help="only the generated takes"
        )

    def handle(self, *args, **options):
        with transaction.atomic():
            users = {name: demo_user(name, superuser) for name, (_, superuser) in USERS.items()}
            project, created = demo_project(users)
        self.stdout.write(f"Project {project.name!r} (id {project.pk}), "
                          f"{project.labels.count()} labels"
                          + ("" if created else "; members and labels as its admins left them"))
        outcomes = [self.add_synth(project, users["annotator"], seed, seconds)
                    for seed, seconds in SYNTH_TAKES]
        if not options["no_shared_data"]:
            outcomes += self.add_cmu(project, users["annotator"], options["shared_data"])
        for outcome in outcomes:
            self.show(outcome)
        self.stdout.write(f"Demo logins (password for all: {PASSWORD}):")
        for name, (role, superuser) in USERS.items():
            extra = ", Django admin" if superuser else ""
            self.stdout.write(f"  {name:<10} {role}{extra}")

    def add_synth(self, project, user, seed, seconds):
        take, _segments = synth.generate(seed=seed, fps=120.0, duration=seconds)
        text = io.StringIO()
        write_bvh(take, text)
        upload = ContentFile(text.getvalue().encode(), name=f"synth-{seed}-{seconds:.0f}s.bvh")
        capture, created = services.do_upload_capture(project, user, upload)
        return importing.Outcome(Path(upload.name), "imported" if created else "duplicate",
                                 capture=capture)

    def add_cmu(self, project, user, folder):
        folder = folder or data_dir()
        if not folder.is_dir():
            self.stdout.write(f"No CMU takes: {folder} not found (only generated takes added)")
            return []
        return [
            importing.import_file(project, user, folder / path,
                                  asf=folder / asf if asf else None, check=False)
            for path, asf in CMU_TAKES
        ]

    def show(self, outcome):
        if outcome.status == "failed":
            self.stdout.write(self.style.WARNING(f"  skipped  {outcome.reason}"))
            return
        capture = outcome.capture
        verb = "added   " if outcome.status == "imported" else "present "
        self.stdout.write(f"  {verb} {capture.name} (capture {capture.pk}, {capture.status})")


def demo_user(username, superuser):
    """The demo user, created with the demo password the first time only."""
    users = get_user_model().objects
    user = users.filter(username=username).first()
    if user is None:
        create = users.create_superuser if superuser else users.create_user
        user = create(username, email="", password=PASSWORD)
    return user


def demo_project(users):
    """``(project, created)``: the demo project, made with its members and label taxonomy the
    first time only; an existing one is left as it is."""
    project = Project.objects.filter(name=PROJECT).order_by("id").first()
    if project is not None:
        return project, False
    project = services.do_create_project(users["admin"], PROJECT)
    for name, (role, _) in USERS.items():
        if name != "admin":
            services.do_set_member(project, name, role)
    for name, color, hotkey in LABELS:
        services.do_add_label(project, name, color, hotkey)
    return project, True
