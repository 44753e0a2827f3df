"""A small installation with something of everything an operator must not lose, built through
the services as people and workers build it; and what it holds, as its users see it.

Used by the backup tests (build, back up, restore elsewhere, compare) and by
``tests/segmentation/upgrade/make_fixture.py``, which runs :func:`populate` with the previous
release's code to make the upgrade fixture. It uses only services that release has.

:func:`populate`: three people (alice admin, bob annotator, rachel reviewer), one project with
labels, two synthetic takes (``motionlib.synth``) uploaded, ingested and detected in-process,
bob's submitted reviews (so library segments), rachel's review in progress, a gold version of
the first take, a trained cut model and the project's similar-clip index.
"""

import io
import json

from django.contrib.auth import get_user_model
from django.core.files.uploadedfile import SimpleUploadedFile

TAKES = (("walk_punch.bvh", 1), ("kick_jump.bvh", 2))


def synthetic_bvh(seed):
    from motionlib import synth, write_bvh

    take, _ = synth.generate(seed=seed, fps=60.0, n_segments=4, segment_seconds=(2.0, 3.0))
    text = io.StringIO()
    write_bvh(take, text)
    return text.getvalue().encode()


def populate():
    """Build the installation (in an empty database); returns its project."""
    from segmentation import services
    from segmentation.services.gold import do_save_gold
    from segmentation.similar import updates

    users = get_user_model().objects
    alice = users.create_user("alice", password="alice-password", is_staff=True)
    bob = users.create_user("bob", password="bob-password")
    rachel = users.create_user("rachel", password="rachel-password")
    project = services.do_create_project(alice, "Studio A")
    services.do_set_member(project, "bob", "annotator")
    services.do_set_member(project, "rachel", "reviewer")
    for name, color, key in (("walk", "#2563eb", "1"), ("punch", "#dc2626", "2")):
        services.do_add_label(project, name, color, key)
    captures = [_ingested(project, alice, name, seed) for name, seed in TAKES]
    for capture in captures:
        _review(capture, bob, ["walk", "punch", None, "walk", "punch"], submit=True)
    _review(captures[0], rachel, ["punch", "walk"], submit=False)
    first = captures[0]
    bobs = first.reviews.get(annotator=bob)
    cuts = sorted(c.frame for c in bobs.cuts.exclude(fate="deleted"))
    gold_labels = [("walk", "punch")[i % 2] for i in range(len(cuts) + 1)]
    do_save_gold(first, alice, cuts, gold_labels, 0, source_review=bobs)
    _train(project)
    updates.build(project.pk)
    return project


def _ingested(project, user, name, seed):
    from tests.segmentation.base import ingested

    return ingested(project, user, SimpleUploadedFile(name, synthetic_bvh(seed)))


def _review(capture, user, labels, submit):
    """``user``'s review of the detected cuts with ``labels`` on its first segments; one cut
    moved and one inserted, so a review is more than its candidates."""
    from segmentation import services

    review = services.get_or_create_review(capture, user)
    cuts = list(review.cuts.order_by("frame"))
    services.do_change_cut(review, user, cuts[0], review.version, frame=cuts[0].frame + 3)
    services.do_insert_cut(review, user, (cuts[-1].frame + capture.n_frames) // 2,
                           review.version)
    for index, name in enumerate(labels):
        if name is not None:
            services.do_label_segment(review, user, index, name, review.version)
    if submit:
        services.do_submit_review(review, user, review.version)
    return review


def _train(project):
    from segmentation import tasks
    from segmentation.models import ProjectCutModel
    from segmentation.services.adaptation import request_training

    job = (ProjectCutModel.objects.filter(project=project, status="queued").first()
           or request_training(project.pk))
    tasks.retrain(job.pk)


def library_exports(client):
    """What alice downloads, by file name: the zip of every library segment, each segment's
    BVH and similar clips, and each project's cut models."""
    files = {"segments.zip": _body(client.get("/api/segments/export.zip"))}
    page = "/api/segments/"
    while page:
        listing = client.get(page).json()
        for segment in listing["results"]:
            base = f"/api/segments/{segment['id']}/"
            files[f"{segment['id']}.bvh"] = _body(client.get(base + "export.bvh"))
            files[f"{segment['id']}.similar.json"] = _body(client.get(base + "similar/"))
        page = listing.get("next")
    for project in client.get("/api/projects/").json():
        files[f"project-{project['id']}-cut-models.json"] = _body(
            client.get(f"/api/projects/{project['id']}/cut-models/"))
    return files


def holdings(client):
    """What the installation's people see of their work, through the API as alice: per
    project its label names and cut models; per capture, every review's cuts and segment
    labels (by name) and the gold version; the library's segments. Fields other releases may add are left out, so an upgrade that
    keeps the work keeps this unchanged."""
    captures = {}
    page = "/api/captures/"
    while page:
        listing = client.get(page).json()
        for capture in listing["results"]:
            captures[capture["name"]] = _capture_work(client, capture)
        page = listing.get("next")
    segments, page = [], "/api/segments/"
    while page:
        listing = client.get(page).json()
        segments += [_segment(s) for s in listing["results"]]
        page = listing.get("next")
    projects = {project["name"]: {
        "labels": sorted(_name(label) for label in project["labels"]),
        "cut_models": [
            {k: m[k] for k in ("version", "status", "n_takes", "n_cuts")}
            for m in client.get(f"/api/projects/{project['id']}/cut-models/").json()],
    } for project in client.get("/api/projects/").json()}
    return {"projects": projects, "captures": captures,
            "library": sorted(segments, key=json.dumps)}


def _capture_work(client, capture):
    reviews = client.get(f"/api/captures/{capture['id']}/reviews/").json()
    gold = client.get(f"/api/captures/{capture['id']}/adjudication/").json()["gold"]
    return {
        "status": capture["status"], "n_frames": capture["n_frames"], "fps": capture["fps"],
        "reviews": {r["annotator"]["username"]: {
            "status": r["status"],
            "cuts": [{k: c[k] for k in ("origin", "fate", "candidate_frame", "frame")}
                     for c in r["cuts"]],
            "segments": [(s["start"], s["stop"], _name(s["label"])) for s in r["segments"]],
        } for r in reviews},
        "gold": gold and {
            "version": gold["version"], "cuts": gold["cuts"],
            "segments": [(s["start"], s["stop"], _name(s["label"])) for s in gold["segments"]],
        },
    }


def _segment(segment):
    return {"capture": segment["capture"]["name"], "start": segment["start"],
            "stop": segment["stop"], "label": _name(segment["label"]),
            "gold": segment["gold"], "superseded": segment["superseded"],
            "annotator": (segment["annotator"] or {}).get("username"),
            "agreement": segment["agreement"]}


def _name(label):
    """A label's name, whether the API gives the name or the label ({"name": …})."""
    return label["name"] if isinstance(label, dict) else label


def _body(response):
    assert response.status_code == 200, response.content
    if response.streaming:
        return b"".join(response.streaming_content)
    return response.content


def main(what, out):
    """For the installation this process's environment configures: write alice's downloads
    into the folder ``out`` (``exports``), or its :func:`holdings` as JSON to the file
    ``out`` (``holdings``)."""
    import django

    django.setup()
    from pathlib import Path

    from rest_framework.test import APIClient

    client = APIClient()
    client.force_authenticate(get_user_model().objects.get(username="alice"))
    if what == "holdings":
        Path(out).write_text(json.dumps(holdings(client), indent=1, sort_keys=True) + "\n")
        return
    for name, data in library_exports(client).items():
        (Path(out) / name).write_bytes(data)


if __name__ == "__main__":
    import sys

    main(*sys.argv[1:])
