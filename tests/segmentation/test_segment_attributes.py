"""Segment attributes (issue 49, item 5): a per-project schema edited by admins, values set
per segment of a review and validated against it, carried into gold versions, filtered in
the library and written in the exports' manifests; a schema change never loses a value."""

import csv
import io
import json
import zipfile

from segmentation.models import GoldAttributeValue, SegmentAttributeValue
from tests.segmentation.base import BaseTestCase, synthetic_bvh


class AttributesTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture(candidates=(100, 200), n_frames=400)
        self.schema = f"/api/projects/{self.project.pk}/attributes/"
        self.login(self.alice)
        self.quality = self.client.post(self.schema, {"name": "quality", "kind": "choice", "hotkey": "q",
                                                      "options": ["good", "usable", "unusable"]},
                                        format="json").json()
        self.cleanup = self.client.post(self.schema, {"name": "needs cleanup", "kind": "boolean",
                                                      "hotkey": "b"}, format="json").json()
        self.note = self.client.post(self.schema, {"name": "note", "kind": "text"}, format="json").json()
        self.base = f"/api/captures/{self.capture.pk}/review/"
        self.version = 1

    def set(self, index, name, value):
        r = self.client.patch(f"{self.base}segments/{index}/attributes/",
                              {"name": name, "value": value, "version": self.version}, format="json")
        if r.status_code == 200:
            self.version = r.json()["version"]
        return r

    def label_and_submit(self, user):
        self.login(user)
        self.client.post(self.base)
        self.version = 1
        for index, label in enumerate(("walk", "punch", "walk")):
            self.version = self.client.patch(f"{self.base}segments/{index}/", {"label": label, "version": self.version},
                                             format="json").json()["version"]

    def submit(self):
        r = self.client.post(self.base + "submit/", {"version": self.version}, format="json")
        self.assertEqual(r.status_code, 200, r.content)

    def test_only_admins_edit_the_schema_and_members_read_it(self):
        self.login(self.rachel)
        self.assertEqual(self.client.post(self.schema, {"name": "x", "kind": "text"}, format="json").status_code, 403)
        self.assertEqual(self.client.delete(f"{self.schema}{self.note['id']}/").status_code, 403)
        self.login(self.bob)
        self.assertEqual([a["name"] for a in self.client.get(self.schema).json()], ["quality", "needs cleanup", "note"])
        self.login(self.charlie)
        self.assertEqual(self.client.get(self.schema).status_code, 404)

    def test_it_names_a_bad_schema(self):
        for body, needle in (({"name": "a:b", "kind": "text"}, "may not contain ':'"),
                             ({"name": "quality", "kind": "text"}, "already has an attribute 'quality'"),
                             ({"name": "x", "kind": "choice"}, "options: a choice needs a list"),
                             ({"name": "x", "kind": "text", "options": ["a"]}, "only a choice has options"),
                             ({"name": "x", "kind": "text", "hotkey": "a"}, "hotkey: must be one of"),
                             ({"name": "x", "kind": "text", "hotkey": "q"}, "already used by 'quality'")):
            r = self.client.post(self.schema, body, format="json")
            self.assertEqual(r.status_code, 400, body)
            self.assertIn(needle, r.json()["detail"])

    def test_values_are_validated_against_the_schema_and_shown_on_the_segment(self):
        self.login(self.bob)
        self.client.post(self.base)
        for name, value, needle in (("quality", "great", "'great' is not an option of 'quality' (good, usable, unusable)"),
                                    ("needs cleanup", "maybe", "'needs cleanup' is yes or no"),
                                    ("colour", "red", "'colour' is not an attribute of this project"),
                                    ("note", "x" * 501, "at most 500 characters")):
            r = self.set(1, name, value)
            self.assertEqual(r.status_code, 400, name)
            self.assertIn(needle, r.json()["detail"])
        self.assertEqual(self.set(9, "quality", "good").status_code, 400)
        self.set(1, "quality", "usable")
        self.set(1, "needs cleanup", True)
        segment = self.set(1, "note", "=HYPERLINK(1)").json()["segments"][1]
        self.assertEqual(segment["attributes"], {"quality": "usable", "needs cleanup": True, "note": "=HYPERLINK(1)"})
        cleared = self.set(1, "quality", None).json()["segments"][1]["attributes"]
        self.assertNotIn("quality", cleared)

    def test_a_value_follows_its_segment_when_a_cut_moves(self):
        self.login(self.bob)
        self.client.post(self.base)
        self.set(1, "quality", "good")
        cut = self.client.get(self.base).json()["cuts"][0]["id"]
        moved = self.client.patch(f"{self.base}cuts/{cut}/", {"frame": 120, "version": self.version}, format="json").json()
        self.assertEqual(moved["segments"][1]["start"], 120)
        self.assertEqual(moved["segments"][1]["attributes"], {"quality": "good"})

    def test_a_schema_change_refuses_to_drop_values_in_use(self):
        self.login(self.bob)
        self.client.post(self.base)
        self.set(0, "quality", "unusable")
        self.login(self.alice)
        r = self.client.patch(f"{self.schema}{self.quality['id']}/", {"options": ["good", "usable"]}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("'unusable' of 'quality' is set on 1 segment(s)", r.json()["detail"])
        r = self.client.delete(f"{self.schema}{self.quality['id']}/")
        self.assertEqual(r.status_code, 400)
        self.assertIn("'quality' is set on 1 segment(s)", r.json()["detail"])
        r = self.client.patch(f"{self.schema}{self.quality['id']}/", {"kind": "text"}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertEqual(SegmentAttributeValue.objects.get().value, "unusable")
        # Options nobody uses may go, and an attribute nobody uses may be deleted.
        r = self.client.patch(f"{self.schema}{self.quality['id']}/", {"options": ["unusable", "good"]}, format="json")
        self.assertEqual(r.json()["options"], ["unusable", "good"])
        self.assertEqual(self.client.delete(f"{self.schema}{self.note['id']}/").status_code, 204)

    def test_library_filters_and_manifests_carry_the_values(self):
        self.label_and_submit(self.bob)
        self.set(0, "quality", "good")
        self.set(1, "quality", "unusable")
        self.set(1, "needs cleanup", True)
        self.submit()
        self.login(self.alice)
        page = self.client.get("/api/segments/?attribute=quality:unusable").json()
        self.assertEqual([(r["start"], r["attributes"]) for r in page["results"]],
                         [(100, {"quality": "unusable", "needs cleanup": True})])
        self.assertEqual(self.client.get("/api/segments/?attribute=needs cleanup:false").json()["count"], 0)
        both = self.client.get("/api/segments/?attribute=quality:good&attribute=needs cleanup:no").json()
        self.assertEqual(both["count"], 0)
        for query, needle in (("quality:great", "'great' is not an option"), ("colour:red", "no attribute named 'colour'"),
                              ("quality", "write name:value")):
            r = self.client.get(f"/api/segments/?attribute={query}")
            self.assertEqual(r.status_code, 400, query)
            self.assertIn(needle, r.json()["detail"])
        one = self.client.get(f"/api/segments/{page['results'][0]['id']}/").json()
        self.assertEqual(one["attributes"], {"quality": "unusable", "needs cleanup": True})

    def test_the_export_manifests_carry_the_values_neutralised_in_csv(self):
        self.login(self.bob)
        capture = self.ingest(self.upload(synthetic_bvh()).json()["id"])
        self.base, self.version = f"/api/captures/{capture.pk}/review/", 1
        segments = self.client.post(self.base).json()["segments"]
        for segment in segments:
            self.version = self.client.patch(f"{self.base}segments/{segment['index']}/",
                                             {"label": "walk", "version": self.version},
                                             format="json").json()["version"]
        self.set(0, "quality", "unusable")
        self.set(0, "needs cleanup", True)
        self.set(1, "note", "=cmd|' /C calc'!A0")
        self.submit()
        r = self.client.get(f"/api/segments/export.zip?capture={capture.pk}&attribute=quality:unusable")
        archive = zipfile.ZipFile(io.BytesIO(b"".join(r.streaming_content)))
        self.assertEqual([m["attributes"] for m in json.loads(archive.read("manifest.json"))],
                         [{"quality": "unusable", "needs cleanup": True}])
        r = self.client.get(f"/api/segments/export.zip?capture={capture.pk}")
        archive = zipfile.ZipFile(io.BytesIO(b"".join(r.streaming_content)))
        by_start = {m["start"]: m["attributes"] for m in json.loads(archive.read("manifest.json"))}
        self.assertEqual(by_start[segments[1]["start"]], {"note": "=cmd|' /C calc'!A0"})
        rows = list(csv.DictReader(io.StringIO(archive.read("manifest.csv").decode())))
        self.assertEqual([(r["attribute:quality"], r["attribute:needs cleanup"], r["attribute:note"])
                          for r in rows[:2]],
                         [("unusable", "true", ""), ("", "", "'=cmd|' /C calc'!A0")])

    def test_gold_keeps_the_values_of_the_review_it_copies(self):
        self.label_and_submit(self.bob)
        self.set(1, "quality", "good")
        self.submit()
        review = self.client.get(self.base).json()["id"]
        self.login(self.rachel)
        r = self.client.put(f"/api/captures/{self.capture.pk}/adjudication/",
                            {"cuts": [100, 200], "labels": ["walk", "punch", "walk"], "version": 0,
                             "source_review": review}, format="json")
        self.assertEqual(r.status_code, 200, r.content)
        self.assertEqual(list(GoldAttributeValue.objects.values_list("start", "value")), [(100, "good")])
        gold = self.client.get("/api/segments/?gold=true&attribute=quality:good").json()["results"]
        self.assertEqual([g["start"] for g in gold], [100])
        # Saved again with the segment unchanged, it keeps them; explicit ones are validated.
        self.client.put(f"/api/captures/{self.capture.pk}/adjudication/",
                        {"cuts": [100, 200], "labels": ["walk", "punch", "walk"], "version": 1}, format="json")
        self.assertEqual(GoldAttributeValue.objects.count(), 1)
        r = self.client.put(f"/api/captures/{self.capture.pk}/adjudication/",
                            {"cuts": [100, 200], "labels": ["walk", "punch", "walk"], "version": 2,
                             "attributes": [{}, {"quality": "superb"}, {}]}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("attributes: segment 1: 'superb' is not an option of 'quality'", r.json()["detail"])

    def test_a_capture_and_a_project_whose_segments_carry_values_can_still_be_deleted(self):
        self.label_and_submit(self.bob)
        self.set(1, "quality", "good")
        self.submit()
        other = self.ready_capture(candidates=(50,), n_frames=100, name="d.bvh")
        self.client.post(f"/api/captures/{other.pk}/review/")
        self.client.patch(f"/api/captures/{other.pk}/review/segments/0/attributes/",
                          {"name": "quality", "value": "usable", "version": 1}, format="json")
        self.capture.delete()
        self.assertEqual(list(SegmentAttributeValue.objects.values_list("value", flat=True)), ["usable"])
        self.project.delete()
        self.assertFalse(SegmentAttributeValue.objects.exists())

    def test_gold_takes_a_segment_the_reviews_agree_on_and_none_where_they_differ(self):
        from django.contrib.auth import get_user_model

        from segmentation import services
        get_user_model().objects.create_user("dora")
        services.do_set_member(self.project, "dora", "annotator")
        dora = get_user_model().objects.get(username="dora")
        for user, quality in ((self.bob, "good"), (dora, "usable")):
            self.label_and_submit(user)
            self.set(0, "needs cleanup", True)
            self.set(1, "quality", quality)
            self.submit()
        self.login(self.rachel)
        r = self.client.put(f"/api/captures/{self.capture.pk}/adjudication/",
                            {"cuts": [100, 200], "labels": ["walk", "punch", "walk"], "version": 0},
                            format="json")
        self.assertEqual(r.status_code, 200, r.content)
        self.assertEqual(list(GoldAttributeValue.objects.values_list("start", "value")), [(0, "true")])

    def test_a_huge_or_odd_value_is_named_short_never_echoed_whole(self):
        self.login(self.bob)
        self.client.post(self.base)
        for name, value in (("quality", "x" * 100_000), ("note", {"a": ["b"] * 10_000}), ("needs cleanup", [1] * 10_000)):
            r = self.set(0, name, value)
            self.assertEqual(r.status_code, 400, name)
            self.assertLess(len(r.json()["detail"]), 300)
            self.assertIn(name, r.json()["detail"])

    def test_a_common_value_and_a_rare_one_filter_the_same_way(self):
        from unittest import mock

        from segmentation.queries import library
        self.label_and_submit(self.bob)
        self.set(0, "quality", "good")
        self.set(2, "quality", "good")
        self.submit()
        self.login(self.alice)
        url = "/api/segments/?attribute=quality:good&page_size=1"
        rare = [self.client.get(f"{url}&page={n}").json()["results"][0]["start"] for n in (1, 2)]
        with mock.patch.object(library, "COMMON_VALUE_ROWS", 1):
            common = [self.client.get(f"{url}&page={n}").json()["results"][0]["start"] for n in (1, 2)]
        self.assertEqual(rare, common)
        self.assertEqual(sorted(rare), [0, 200])
