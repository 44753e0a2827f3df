"""Writing a project's similar-clip index: ``build`` (a new generation from the whole
library) and ``update`` (append what changed since, or compact), and queueing an update
when the library changes."""

import logging
import time

import numpy as np
from django.db import transaction

from motionlib import similarity, vector_index
from motionlib.errors import InputError
from segmentation import workers
from segmentation.models import LibrarySegment
from segmentation.similar.files import (
    FORMAT,
    IndexUnusable,
    as_vectors,
    described,
    fingerprint_of,
    folder_of,
    index_dir,
    locked,
    manifest_path,
    publish,
    read_manifest,
    remove_generations,
)

log = logging.getLogger(__name__)

# An update compacts (retrains and rewrites the generation) once the added and removed
# records outnumber this share of the base: a search compares the query with every added
# vector, and clusters drift as the library changes.
COMPACT_SHARE = 0.05
# ... and never for fewer records than this (a small library would compact at each update).
COMPACT_MIN = 2000
READ_CHUNK = 20000


def _chunks(queryset):
    """(ids, profile vectors, descriptor bytes) of a queryset of described segments,
    READ_CHUNK rows at a time, by id."""
    last = 0
    while True:
        rows = list(queryset.filter(id__gt=last).order_by("id")
                    .values_list("id", "profile", "descriptor")[:READ_CHUNK])
        if not rows:
            return
        last = rows[-1][0]
        missing = [r[0] for r in rows if r[2] is None]
        if missing:
            raise IndexUnusable(f"segments {missing[:5]}: a profile without a descriptor; "
                                "rebuild the library's descriptors")
        yield (np.array([r[0] for r in rows], dtype=np.int64), as_vectors([r[1] for r in rows]),
               [bytes(r[2]) for r in rows])


def _descriptor_rows(blobs, width):
    """(n, width) float32 descriptors from their bytes; IndexUnusable when one differs."""
    sizes = {len(b) for b in blobs}
    if sizes - {4 * width}:
        raise IndexUnusable(f"segment descriptors have {sorted(n // 4 for n in sizes)} numbers, "
                            f"the index {width}; rebuild the library's descriptors")
    return np.frombuffer(b"".join(blobs), dtype="<f4").reshape(len(blobs), width)


def build(project_id):
    """Write a project's index from scratch; returns the manifest (None: nothing to index)."""
    with locked(project_id):
        return _build(project_id)


def _build(project_id):
    """Read the described segments once, by id: profiles into memory (for training),
    descriptors straight into the payload file (a million are several GB)."""
    fingerprint = fingerprint_of(project_id)
    index_dir().mkdir(parents=True, exist_ok=True)
    payload = index_dir() / f"project_{project_id}.payload.tmp"
    id_parts, vector_parts, width = [], [], None
    try:
        with open(payload, "wb") as out:
            for ids, vectors, blobs in _chunks(described(project_id)):
                width = width or len(blobs[0]) // 4
                if id_parts and vectors.shape[1] != vector_parts[0].shape[1]:
                    raise IndexUnusable(f"project {project_id}: segment profiles have "
                                        f"{sorted({vector_parts[0].shape[1], vectors.shape[1]})} "
                                        "numbers; rebuild the library's descriptors")
                out.write(_descriptor_rows(blobs, width).tobytes())
                id_parts.append(ids)
                vector_parts.append(vectors)
        if not id_parts:
            manifest_path(project_id).unlink(missing_ok=True)
            remove_generations(project_id, keep=None)
            return None
        ids = np.concatenate(id_parts)
        vectors = np.concatenate(vector_parts)
        del id_parts, vector_parts
        generation = time.time_ns()
        name = f"project_{project_id}.g{generation}"
        state = vector_index.build(index_dir() / name, ids, vectors, seed=project_id,
                                   payload=payload, payload_width=width)
    finally:
        payload.unlink(missing_ok=True)
    lists = state.pop("lists")
    manifest = publish(project_id, {
        "format": FORMAT, "file": name, "generation": generation, "state": state,
        "count": len(ids), "lists": lists, "max_id": int(ids[-1]), "fingerprint": fingerprint,
        "built_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())})
    remove_generations(project_id, keep=name)
    log.info("similar index of project %s built: %s vectors", project_id, manifest["count"])
    return manifest


def update(project_id):
    """Bring a project's index in step with the database: append the vectors of segments
    it lacks and the keys of deleted ones. Compacts (``build``) when there is no usable
    index, or the appended records would outgrow ``COMPACT_SHARE`` of the base.
    Returns the manifest (unchanged when in step)."""
    with locked(project_id):
        try:
            manifest = read_manifest(project_id)
            index = vector_index.VectorIndex.open(folder_of(manifest), manifest["state"])
        except (IndexUnusable, InputError) as exc:
            log.info("similar index of project %s rebuilt: %s", project_id, exc)
            return _build(project_id)
        fingerprint = fingerprint_of(project_id)
        if fingerprint == manifest.get("fingerprint"):
            return manifest
        keys = index.keys()
        ids = np.fromiter(described(project_id).values_list("id", flat=True).iterator(chunk_size=20000),
                          dtype=np.int64)
        removed = np.setdiff1d(keys, ids, assume_unique=True)
        added = np.setdiff1d(ids, keys, assume_unique=True)
        state = manifest["state"]
        appended = state["delta"] + state["removed"] + len(added) + len(removed)
        if appended > max(COMPACT_MIN, COMPACT_SHARE * state["base"]):
            return _build(project_id)
        add_ids, add_vectors, add_blobs = [], [], []
        for first in range(0, len(added), READ_CHUNK):
            part = [int(i) for i in added[first:first + READ_CHUNK]]
            rows = {pk: (profile, descriptor) for pk, profile, descriptor in LibrarySegment.objects
                    .filter(pk__in=part).values_list("id", "profile", "descriptor")}
            part = [pk for pk in part if pk in rows]  # deleted meanwhile
            add_ids += part
            add_vectors += [rows[pk][0] for pk in part]
            add_blobs += [bytes(rows[pk][1]) for pk in part]
        vectors = as_vectors(add_vectors, index.ndim // similarity.PROFILE_ROWS)
        if len(vectors) and (vectors.shape[1] != index.ndim
                             or {len(b) for b in add_blobs} != {4 * state["payload"]}):
            return _build(project_id)
        payload = _descriptor_rows(add_blobs, state["payload"]) if add_blobs else None
        state = vector_index.append(folder_of(manifest), state, add_ids, vectors, removed,
                                    add_payload=payload)
        max_id = max(int(ids.max()) if len(ids) else 0, manifest["max_id"])
        return publish(project_id, {**manifest, "state": state, "max_id": max_id,
                                     "count": len(keys) - len(removed) + len(add_ids),
                                     "fingerprint": fingerprint})


def schedule_update(project_id):
    """Queue ``update`` for when the current transaction commits (a worker must see the
    rows). A broker that cannot be reached costs freshness of the file only: searches
    read newer segments from the database."""
    transaction.on_commit(lambda: workers.send(
        "update_similar_index", project_id, then="searches read the newer segments from the database"))
