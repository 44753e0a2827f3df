"""The similar-clip vector index: it finds what the exact scan finds, sees segments added
after it was written, is brought in step when reviews are submitted, and is rebuilt when
its file is lost."""

from unittest import mock

import numpy as np
import pytest
from django.core.management import call_command
from django.db import connection
from django.test.utils import CaptureQueriesContext

import motionlib
from motionlib import similarity, synth, vector_index
from motionlib.vector_index import VectorIndex
from segmentation import services, tasks
from segmentation.models import Capture, LibrarySegment
from segmentation.similar import candidates, descriptors, files, index, search, updates
from tests.segmentation.base import BaseTestCase
from tests.segmentation.test_library import submit_review


def synth_descriptors(n, seed=3):
    """``n`` descriptors of random spans (0.3-3 s) of a seeded synthetic take."""
    take, _ = synth.generate(seed=seed, duration=90)
    positions = motionlib.forward_kinematics(take)
    joints = motionlib.canonical_indices(take)
    scale = similarity.body_scale(positions, joints)
    rng = np.random.default_rng(seed)
    spans = []
    for _ in range(n):
        length = int(rng.uniform(0.3, 3.0) * take.fps)
        start = int(rng.integers(0, len(positions) - length))
        spans.append((start, start + length))
    return spans, [similarity.segment_descriptor(positions, joints, a, b, fps=take.fps, scale=scale)
                   for a, b in spans]


class SimilarIndexTestCase(BaseTestCase):
    N = 300

    def setUp(self):
        super().setUp()
        # Clusters of 16 (a million-segment library has 1024 per cluster), so a search
        # scans only some of them here too.
        patcher = mock.patch.object(vector_index, "LIST_SIZE", 16)
        patcher.start()
        self.addCleanup(patcher.stop)

    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        cls.spans, cls.descs = synth_descriptors(cls.N)

    def add_segments(self, spans, descs, annotator=None):
        capture = self.ready_capture(name=f"c{LibrarySegment.objects.count()}.bvh", n_frames=20000)
        rows = []
        for (start, stop), desc in zip(spans, descs, strict=True):
            row = LibrarySegment(project=self.project, capture=capture, annotator=annotator or self.bob,
                                 label=self.walk, start=start, stop=stop,
                                 duration=(stop - start) / 120)
            descriptors.store_descriptor(row, desc)
            rows.append(row)
        return LibrarySegment.objects.bulk_create(rows)

    def visible(self):
        return LibrarySegment.objects.visible_to(self.rachel).preferred()

    def exact(self, segment, k=10):
        """The exact scan: ``similar`` while the project has no index."""
        files.manifest_path(self.project.pk).unlink(missing_ok=True)
        index.forget()
        assert index.open_index(self.project.pk) is None
        return [(s.pk, round(d, 5)) for s, d in search.similar(segment, self.visible(), k=k)]

    def indexed(self, segment, k=10):
        assert index.open_index(self.project.pk) is not None
        return [(s.pk, round(d, 5)) for s, d in search.similar(segment, self.visible(), k=k)]


class SameResultsTest(SimilarIndexTestCase):
    def test_it_returns_the_same_clips_as_the_exact_scan(self):
        rows = self.add_segments(self.spans, self.descs)
        queries = rows[::30]
        expected = [self.exact(q) for q in queries]
        updates.build(self.project.pk)
        index.forget()
        assert [self.indexed(q) for q in queries] == expected
        assert all(len(found) == 10 for found in expected)

    def test_it_leaves_out_segments_the_caller_may_not_see(self):
        dana_rows = self.add_segments(self.spans[:150], self.descs[:150], annotator=self.alice)
        bob_rows = self.add_segments(self.spans[150:], self.descs[150:])
        updates.build(self.project.pk)
        # bob (an annotator) sees his own segments only; alice's are nearer to her own query.
        visible = LibrarySegment.objects.visible_to(self.bob).preferred()
        found = search.similar(dana_rows[0], visible, k=10)
        assert len(found) == 10
        assert {s.pk for s, _ in found} <= {r.pk for r in bob_rows}


class ShownTest(SimilarIndexTestCase):
    def test_it_shows_each_result_as_the_exact_scan_does(self):
        rows = self.add_segments(self.spans[:60], self.descs[:60])
        self.add_segments(self.spans[60:90], self.descs[60:90], annotator=self.alice)
        LibrarySegment.objects.filter(pk__in=[r.pk for r in rows[1::2]]).update(
            agreement=0.5, is_gold=True, annotator=None)
        self.login(self.rachel)
        url = f"/api/segments/{rows[0].pk}/similar/?k=30"
        exact = self.client.get(url).json()
        updates.build(self.project.pk)
        assert index.open_index(self.project.pk) is not None
        assert self.client.get(url).json() == exact
        assert len(exact["results"]) == 30


class AccessTest(SimilarIndexTestCase):
    """What the endpoint shows each role, through the index and without it: the segment's
    project and the role the user has there decide both the query and the results."""

    def setUp(self):
        super().setUp()
        self.alices = self.add_segments(self.spans[:40], self.descs[:40], annotator=self.alice)
        self.bobs = self.add_segments(self.spans[40:80], self.descs[40:80])
        self.gold = self.add_segments(self.spans[80:100], self.descs[80:100])
        LibrarySegment.objects.filter(pk__in=[r.pk for r in self.gold]).update(
            is_gold=True, annotator=None)

    def both_paths(self, check):
        check()
        updates.build(self.project.pk)
        index.forget()
        assert index.open_index(self.project.pk) is not None
        check()

    def ids(self, segment, user, k=50):
        self.login(user)
        response = self.client.get(f"/api/segments/{segment.pk}/similar/?k={k}")
        assert response.status_code == 200, response.content
        return {r["id"] for r in response.json()["results"]}

    def status(self, segment, user):
        if user is None:
            self.client.force_authenticate(None)
        else:
            self.login(user)
        return self.client.get(f"/api/segments/{segment.pk}/similar/").status_code

    def test_an_annotator_compares_with_own_and_gold_segments_only(self):
        def check():
            found = self.ids(self.bobs[0], self.bob)
            assert found and found <= {r.pk for r in self.bobs + self.gold}
            assert found & {r.pk for r in self.gold}
            assert self.ids(self.gold[0], self.bob) <= {r.pk for r in self.bobs + self.gold}
        self.both_paths(check)

    def test_a_reviewer_compares_with_everyone_s(self):
        def check():
            found = self.ids(self.bobs[0], self.rachel, k=100)
            assert found & {r.pk for r in self.alices} and found & {r.pk for r in self.bobs}
        self.both_paths(check)

    def test_it_refuses_a_segment_the_user_may_not_see(self):
        def check():
            assert self.status(self.alices[0], self.bob) == 404  # another annotator's
            assert self.status(self.bobs[0], self.charlie) == 404  # not a member
            assert self.status(self.bobs[0], None) in (401, 403)
            LibrarySegment.objects.filter(pk=self.bobs[1].pk).delete()
            assert self.status(self.bobs[1], self.rachel) == 404
        self.both_paths(check)


def needs_postgres():
    if connection.vendor != "postgresql":
        pytest.skip("needs PostgreSQL: DATABASE_URL=postgres://… (make pytest sets it)")


@pytest.mark.integration
class PostgresAccessTest(AccessTest):
    """The same refusals on PostgreSQL, where the view reads through compiled statements
    (``segmentation.db.statements``)."""

    def setUp(self):
        needs_postgres()
        super().setUp()


@pytest.mark.integration
class PostgresStatementPathTest(SimilarIndexTestCase):
    """On PostgreSQL the view reads its segment and the candidates through statements
    compiled once per role and kind; it finds what the queryset path finds, for each role,
    with segments newer than the index, and with takes of bare points beside bodies."""

    def setUp(self):
        needs_postgres()
        super().setUp()

    def test_the_view_finds_what_the_queryset_path_finds(self):
        bobs = self.add_segments(self.spans[:120], self.descs[:120])
        alices = self.add_segments(self.spans[120:240], self.descs[120:240], annotator=self.alice)
        LibrarySegment.objects.filter(pk__in=[r.pk for r in alices[1::4]]).update(
            is_gold=True, annotator=None)
        updates.build(self.project.pk)
        index.forget()
        newer = self.add_segments(self.spans[240:], self.descs[240:])
        # The newest take is one of bare points: compared with its own kind only.
        Capture.objects.filter(pk=newer[0].capture_id).update(
            skeleton={"kind": "points", "marker_set": None, "points": []})
        queries = [bobs[0], bobs[50], alices[0], newer[0], newer[30]]
        seen = 0
        for user in (self.rachel, self.bob, self.alice):
            self.login(user)
            visible = LibrarySegment.objects.visible_to(user).preferred()
            for query in queries:
                response = self.client.get(f"/api/segments/{query.pk}/similar/?k=12")
                if not visible.filter(pk=query.pk).exists():
                    assert response.status_code == 404
                    continue
                query = LibrarySegment.objects.select_related("capture").get(pk=query.pk)
                expected = [(s.pk, round(d, 4)) for s, d in search.similar(query, visible, k=12)]
                found = [(r["id"], r["distance"]) for r in response.json()["results"]]
                assert found == expected, (user.username, query.pk)
                assert found
                seen += 1
                kinds = {query.capture_id == newer[0].capture_id}
                assert {LibrarySegment.objects.get(pk=pk).capture_id == newer[0].capture_id
                        for pk, _ in found} == kinds
        assert seen == 14  # bob may not see alice's segment; the rest are answered


class QueryCountTest(SimilarIndexTestCase):
    def test_it_answers_with_the_same_number_of_queries_whatever_k(self):
        rows = self.add_segments(self.spans[:100], self.descs[:100])
        updates.build(self.project.pk)
        self.login(self.rachel)
        self.client.get(f"/api/segments/{rows[0].pk}/similar/")  # opens and checks the index
        counts = []
        for k in (2, 20):
            with CaptureQueriesContext(connection) as queries:
                response = self.client.get(f"/api/segments/{rows[0].pk}/similar/?k={k}")
            assert response.status_code == 200 and len(response.json()["results"]) == k
            counts.append(len(queries))
        assert counts[0] == counts[1]


class ReadsTest(SimilarIndexTestCase):
    def test_it_reads_the_descriptors_of_the_shortlist_only(self):
        rows = self.add_segments(self.spans, self.descs)
        updates.build(self.project.pk)
        index.forget()
        expected = self.indexed(rows[7])
        opened = index.open_index(self.project.pk)
        asked, proposed = [], []
        read, nearest = opened.descriptors, opened.nearest

        def spy_read(ids):
            asked.append(list(ids))
            return read(ids)

        def spy_nearest(vector, count):
            found = nearest(vector, count)
            proposed.append(len(found[0]))
            return found

        with mock.patch.object(opened, "descriptors", spy_read), \
                mock.patch.object(opened, "nearest", spy_nearest), \
                CaptureQueriesContext(connection) as queries:
            assert self.indexed(rows[7]) == expected
        # The index proposed MIN_CANDIDATES, their profiles with them; only the SHORTLIST
        # nearest were read whole, from the index, and no descriptor from the database.
        assert proposed == [candidates.MIN_CANDIDATES]
        assert [len(ids) for ids in asked] == [search.SHORTLIST]
        assert not [q for q in queries if '"descriptor"' in q["sql"]]


class IncrementalTest(SimilarIndexTestCase):
    def test_it_finds_segments_added_after_the_index_was_written(self):
        rows = self.add_segments(self.spans[:200], self.descs[:200])
        updates.build(self.project.pk)
        assert self.indexed(rows[0])  # the process has seen this index generation
        # The same motion again, in another capture, newer than the index file.
        twin = self.add_segments([self.spans[0]], [self.descs[0]])[0]
        found = self.indexed(rows[0], k=3)
        assert found[0] == (twin.pk, 0.0)
        assert files.read_manifest(self.project.pk)["max_id"] < twin.pk

    def test_a_process_reads_the_newer_segments_once_for_every_caller(self):
        rows = self.add_segments(self.spans[:200], self.descs[:200])
        updates.build(self.project.pk)
        # Twins of the first 20, newer than the index, alice's: bob may not see them.
        twins = self.add_segments(self.spans[:20], self.descs[:20], annotator=self.alice)
        bobs = LibrarySegment.objects.visible_to(self.bob).preferred()
        found = search.similar(rows[0], bobs, k=10)
        assert len(found) == 10 and not {s.pk for s, _ in found} & {r.pk for r in twins}
        opened = index.open_index(self.project.pk)
        assert set(opened.newer[1].tolist()) == {r.pk for r in twins}, "read whatever bob may see"
        # The reviewer's searches find them through what bob's search read, reading no
        # profiles of their own.
        with CaptureQueriesContext(connection) as queries:
            indexed = [self.indexed(q) for q in rows[:20:4]]
        assert not [q for q in queries if "SELECT u.id, u.profile" in q["sql"]]
        assert index.open_index(self.project.pk).newer[0] == twins[-1].pk
        assert [found[0] for found in indexed] == [(twins[i].pk, 0.0) for i in range(0, 20, 4)]
        assert indexed == [self.exact(q) for q in rows[:20:4]]

    def test_it_finds_newer_segments_of_its_own_project_only(self):
        rows = self.add_segments(self.spans[:50], self.descs[:50])
        updates.build(self.project.pk)
        capture = self.ready_capture(name="theirs.bvh")
        capture.project = self.other_project
        capture.save()
        theirs_label = services.do_add_label(self.other_project, "x")
        theirs = LibrarySegment(project=self.other_project, capture=capture, label=theirs_label,
                                start=0, stop=10, duration=0.1)
        descriptors.store_descriptor(theirs, self.descs[0])
        theirs.save()
        mine = self.add_segments([self.spans[0]], [self.descs[0]])[0]
        found = [pk for pk, _ in self.indexed(rows[0], k=5)]
        assert found[0] == mine.pk
        assert theirs.pk not in found

    def test_it_queues_one_update_when_many_segments_are_newer_than_the_index(self):
        rows = self.add_segments(self.spans[:50], self.descs[:50])
        updates.build(self.project.pk)
        self.add_segments(self.spans[50:53], self.descs[50:53])
        queued = []
        with mock.patch.object(index, "DELTA_LIMIT", 2):
            for _ in range(2):
                with self.captureOnCommitCallbacks() as callbacks:
                    self.indexed(rows[0])
                queued.append(len(callbacks))
        assert queued == [1, 0], "the first search queues the update, the next one does not"

    def test_it_brings_the_index_in_step_when_a_review_is_submitted(self):
        self.add_segments(self.spans, self.descs)
        updates.build(self.project.pk)
        capture = self.ready_capture(name="reviewed.bvh")
        with self.captureOnCommitCallbacks() as callbacks:
            submit_review(capture, self.bob, [100, 200], ["walk", "punch", "walk"])
        assert callbacks, "submitting a review queues an index update"
        LibrarySegment.objects.filter(pk=self.add_segments(self.spans[:1], self.descs[:1])[0].pk).delete()
        gone = list(LibrarySegment.objects.order_by("id").values_list("id", flat=True)[:5])
        LibrarySegment.objects.filter(pk__in=gone).delete()
        tasks.update_similar_index(self.project.pk)  # what the worker runs
        manifest = files.read_manifest(self.project.pk)
        stored = VectorIndex.open(files.folder_of(manifest), manifest["state"])
        ids = set(files.described(self.project.pk).values_list("id", flat=True))
        assert set(stored.keys().tolist()) == ids
        assert manifest["count"] == len(ids) == self.N - 5

    def test_an_update_appends_and_leaves_the_base_file_alone(self):
        rows = self.add_segments(self.spans[:200], self.descs[:200])
        first = updates.build(self.project.pk)
        base = files.folder_of(first) / vector_index.BASE
        before = (base.stat().st_ino, base.read_bytes())
        added = self.add_segments(self.spans[:10], self.descs[:10])  # twins, in another capture
        LibrarySegment.objects.filter(pk=added[0].pk).delete()
        manifest = updates.update(self.project.pk)
        assert manifest["file"] == first["file"]
        assert (base.stat().st_ino, base.read_bytes()) == before
        assert (manifest["state"]["delta"], manifest["state"]["removed"]) == (9, 0)
        assert manifest["max_id"] == added[-1].pk  # found in the index, not as newer rows
        assert self.indexed(rows[1], k=1)[0] == (added[1].pk, 0.0)

    def test_it_compacts_when_the_appended_records_outgrow_their_share(self):
        self.add_segments(self.spans[:100], self.descs[:100])
        first = updates.build(self.project.pk)
        self.add_segments(self.spans[100:], self.descs[100:])
        with mock.patch.object(updates, "COMPACT_MIN", 50):
            manifest = updates.update(self.project.pk)
        assert manifest["file"] != first["file"]
        assert manifest["state"] == {**first["state"], "base": self.N}
        assert (first["state"]["delta"], first["state"]["removed"]) == (0, 0)
        assert (first["lists"], manifest["lists"]) == (6, 18)
        assert not files.folder_of(first).exists()

    def test_an_update_that_dies_before_publishing_leaves_the_last_state_in_force(self):
        rows = self.add_segments(self.spans[:100], self.descs[:100])
        first = updates.build(self.project.pk)
        twin = self.add_segments([self.spans[0]], [self.descs[0]])[0]
        with mock.patch.object(updates, "publish", side_effect=OSError("disk full")):
            with self.assertRaises(OSError):
                updates.update(self.project.pk)
        assert files.read_manifest(self.project.pk) == first
        index.forget()
        assert self.indexed(rows[0], k=1)[0] == (twin.pk, 0.0)  # read from the database
        manifest = updates.update(self.project.pk)
        assert manifest["state"]["delta"] == 1 and manifest["max_id"] == twin.pk

    def test_it_leaves_an_index_in_step_unchanged(self):
        self.add_segments(self.spans[:50], self.descs[:50])
        first = updates.build(self.project.pk)
        assert updates.update(self.project.pk) == first


class RebuildTest(SimilarIndexTestCase):
    def test_it_scans_exactly_and_queues_a_rebuild_when_the_index_file_is_deleted(self):
        rows = self.add_segments(self.spans, self.descs)
        expected = self.exact(rows[7])
        manifest = updates.build(self.project.pk)
        (files.folder_of(manifest) / vector_index.BASE).unlink()
        index.forget()
        with self.captureOnCommitCallbacks() as callbacks:
            assert index.open_index(self.project.pk) is None
            found = [(s.pk, round(d, 5)) for s, d in search.similar(rows[7], self.visible())]
        assert found == expected
        assert callbacks, "a rebuild is queued"
        tasks.update_similar_index(self.project.pk)
        assert self.indexed(rows[7]) == expected

    def test_it_does_not_use_an_index_of_another_format(self):
        self.add_segments(self.spans[:50], self.descs[:50])
        updates.build(self.project.pk)
        path = files.manifest_path(self.project.pk)
        path.write_text(path.read_text().replace('"format": 2', '"format": 1'))
        index.forget()
        assert index.open_index(self.project.pk) is None

    def test_it_rebuilds_every_index_from_the_command(self):
        self.add_segments(self.spans[:50], self.descs[:50])
        call_command("similar_index", "--rebuild", verbosity=0)
        manifest = files.read_manifest(self.project.pk)
        assert manifest["count"] == 50
        assert not files.manifest_path(self.other_project.pk).exists()
