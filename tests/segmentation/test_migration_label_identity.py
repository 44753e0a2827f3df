"""Migration 0016 converts segments that stored a label by name into segments that refer
to the label by id, losing none (issue 33, item 1).

The rows are made in the 0012 schema as the service used to leave them after renaming
``walk`` to ``stroll``: gold and library rows still saying ``walk``, and a new ``walk``
label added since.
"""

from tests.segmentation.migrations import MigrationTestCase

BEFORE = [("segmentation", "0012_library_scale")]
AFTER = [("segmentation", "0016_segment_label_identity")]


class LabelIdentityMigrationTest(MigrationTestCase):
    def setUp(self):
        apps = self.migrate(BEFORE)
        model = lambda name: apps.get_model("segmentation", name)  # noqa: E731
        user = apps.get_model("auth", "User").objects.create(username="rachel")
        project = model("Project").objects.create(name="Studio")
        self.stroll = model("Label").objects.create(project=project, name="stroll")
        self.punch = model("Label").objects.create(project=project, name="punch", position=1)
        self.new_walk = model("Label").objects.create(project=project, name="walk", position=2)
        capture = model("Capture").objects.create(project=project, name="c.bvh", checksum="c",
                                                  format="bvh", fps=120.0, n_frames=400)
        model("Adjudication").objects.create(capture=capture, adjudicator=user, cuts=[100, 250],
                                             labels=["walk", "punch", None])
        segment = model("LibrarySegment").objects

        def row(start, stop, label, name, **extra):
            return segment.create(project=project, capture=capture, label=label, label_name=name,
                                  start=start, stop=stop, duration=(stop - start) / 120, **extra)

        # Gold rows saved while "stroll" was still called "walk".
        row(0, 100, self.stroll, "walk", is_gold=True)
        row(100, 250, self.punch, "punch", is_gold=True)
        # An annotator's row whose label row was gone, and one naming a label nobody has.
        row(0, 120, None, "punch", annotator=user, superseded=True)
        row(120, 400, None, "kick", annotator=user, superseded=True)
        suggestion = model("LabelSuggestion").objects
        suggestion.create(capture=capture, pool="all:1:1", start=0, stop=100, label_name="punch")
        suggestion.create(capture=capture, pool="all:1:1", start=100, stop=200, label_name="gone")
        suggestion.create(capture=capture, pool="all:1:1", start=200, stop=400, label_name="")
        model("CaptureAgreement").objects.create(
            capture=capture, n_reviews=2,
            per_label={"punch": {"overlap": 0.5, "frames": 10}, "gone": {"overlap": 1, "frames": 1}})
        self.apps = self.migrate(AFTER)
        self.model = lambda name: self.apps.get_model("segmentation", name)

    def test_gold_labels_become_the_ids_their_names_meant(self):
        gold = self.model("Adjudication").objects.get()
        assert gold.labels == [self.stroll.pk, self.punch.pk, None]

    def test_every_library_row_is_kept_and_derived_rows_follow(self):
        rows = self.model("LibrarySegment").objects.order_by("start", "stop")
        assert [(r.start, r.stop, r.label.name) for r in rows] == [
            (0, 100, "stroll"), (0, 120, "punch"), (100, 250, "punch"), (120, 400, "kick")]
        # A name no label had becomes a retired label, placed last.
        kick = self.model("Label").objects.get(name="kick")
        assert kick.retired and kick.position == 3
        # Suggestions point at their label; one naming no label is dropped (it is recomputed).
        suggestions = self.model("LabelSuggestion").objects.order_by("start")
        assert [(r.start, r.label_id) for r in suggestions] == [(0, self.punch.pk), (200, None)]
        summary = self.model("CaptureAgreement").objects.get()
        assert summary.per_label == {str(self.punch.pk): {"overlap": 0.5, "frames": 10}}

    def test_it_migrates_back_to_names(self):
        apps = self.migrate(BEFORE)
        gold = apps.get_model("segmentation", "Adjudication").objects.get()
        assert gold.labels == ["stroll", "punch", None]
        names = apps.get_model("segmentation", "LibrarySegment").objects.values_list(
            "start", "label_name")
        assert sorted(names) == [(0, "punch"), (0, "stroll"), (100, "punch"), (120, "kick")]
