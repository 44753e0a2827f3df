"""The files of a project's similar-clip index and their manifest (the layout is described in
``segmentation.similar.index``): where they are, reading and publishing the manifest, one
writer at a time, and removing old generations."""

import fcntl
import json
import os
import shutil
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from django.conf import settings
from django.db.models import Count, Max, Sum

from motionlib import similarity, vector_index
from motionlib.errors import InputError
from segmentation.models import LibrarySegment

FORMAT = 2


class IndexUnusable(Exception):
    """The index of a project cannot be used; the message says why."""


def index_dir() -> Path:
    return Path(settings.SIMILAR_INDEX_DIR)


def manifest_path(project_id) -> Path:
    return index_dir() / f"project_{project_id}.json"


def described(project_id):
    return LibrarySegment.objects.filter(project_id=project_id, profile__isnull=False)


def as_vectors(blobs, n_features=None):
    """(n, PROFILE_ROWS * n_features) float32 profiles from the stored bytes."""
    vectors = np.stack([np.frombuffer(bytes(b), dtype="<f4") for b in blobs]) if blobs else (
        np.zeros((0, similarity.PROFILE_ROWS * (n_features or 0)), dtype=np.float32))
    return vectors


@contextmanager
def locked(project_id):
    """One writer per project and machine (an update and a rebuild never interleave)."""
    index_dir().mkdir(parents=True, exist_ok=True)
    with open(index_dir() / f"project_{project_id}.lock", "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def read_manifest(project_id):
    """The manifest dict, or IndexUnusable naming what is wrong with it."""
    path = manifest_path(project_id)
    try:
        manifest = json.loads(path.read_text())
    except FileNotFoundError as exc:
        raise IndexUnusable(f"{path}: no index yet") from exc
    except (OSError, ValueError) as exc:
        raise IndexUnusable(f"{path}: unreadable ({exc})") from exc
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        raise IndexUnusable(f"{path}: format {manifest.get('format') if isinstance(manifest, dict) else '?'}"
                            f", this version reads format {FORMAT}")
    try:
        vector_index.check(folder_of(manifest), manifest["state"])
    except (KeyError, TypeError) as exc:
        raise IndexUnusable(f"{path}: no {exc} in it") from exc
    except InputError as exc:
        raise IndexUnusable(str(exc)) from exc
    return manifest


def folder_of(manifest) -> Path:
    return index_dir() / str(manifest["file"])


def fingerprint_of(project_id):
    """[count, max id, sum of ids] of the described segments: cheap to compare, and
    changed by any insert or delete."""

    found = described(project_id).aggregate(n=Count("id"), top=Max("id"), total=Sum("id"))
    return [found["n"], found["top"] or 0, int(found["total"] or 0)]


def publish(project_id, manifest):
    """Replace the project's manifest atomically (written, fsynced, renamed)."""
    manifest = {**manifest, "updated_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                "bytes": sum(p.stat().st_size for p in folder_of(manifest).iterdir())}
    tmp = manifest_path(project_id).with_suffix(".json.tmp")
    tmp.write_text(json.dumps(manifest, indent=1))
    vector_index.fsync(tmp)
    os.replace(tmp, manifest_path(project_id))
    vector_index.fsync(index_dir())
    return manifest

def remove_generations(project_id, keep):
    for old in index_dir().glob(f"project_{project_id}.g*"):
        if old.name != keep:
            # Processes that map the old files keep them (unlinked inodes live on).
            shutil.rmtree(old, ignore_errors=True)
