"""One person's FBX conversions take one convert slot at most, so files of theirs that hang
Blender never hold back anybody else's (issue 48, item 5); the real-worker case is in
integration/test_fbx_convert_worker.py."""

from django.core.files.base import ContentFile

from segmentation.models import Capture
from tests.segmentation.base import BaseTestCase


class OneConvertSlotTestCase(BaseTestCase):
    def fbx(self, user, name):
        capture = Capture(project=self.project, uploaded_by=user, name=name, format="fbx",
                          checksum=name)
        capture.original.save(name, ContentFile(b"Kaydara FBX Binary"), save=False)
        capture.save()
        return capture

    def test_a_persons_second_conversion_waits_for_the_first(self):
        first, second = self.fbx(self.bob, "a.fbx"), self.fbx(self.bob, "b.fbx")
        self.assertTrue(Capture.objects.claim(first.pk, "slot-1"))
        self.assertFalse(Capture.objects.claim(second.pk, "slot-2"))
        self.assertEqual(Capture.objects.get(pk=second.pk).status, "queued")
        self.assertEqual(Capture.objects.get(pk=first.pk).next_in_line(), second)

    def test_another_persons_conversion_starts_at_once(self):
        self.assertTrue(Capture.objects.claim(self.fbx(self.bob, "a.fbx").pk, "slot-1"))
        self.assertTrue(Capture.objects.claim(self.fbx(self.alice, "c.fbx").pk, "slot-2"))

    def test_the_wait_ends_when_the_first_ends(self):
        first, second = self.fbx(self.bob, "a.fbx"), self.fbx(self.bob, "b.fbx")
        Capture.objects.claim(first.pk, "slot-1")
        Capture.objects.get(pk=first.pk).fail("Blender stopped")
        self.assertTrue(Capture.objects.claim(second.pk, "slot-2"))

    def test_ingest_is_not_held_to_it(self):
        first = self.fbx(self.bob, "a.fbx")
        Capture.objects.claim(first.pk, "slot-1")
        converted = self.fbx(self.bob, "b.fbx")
        Capture.objects.filter(pk=converted.pk).update(converted="derived/x/take.npz")
        self.assertTrue(Capture.objects.claim(converted.pk, "slot-2"))

    def test_a_conversion_that_succeeded_sends_the_next(self):
        first, second = self.fbx(self.bob, "a.fbx"), self.fbx(self.bob, "b.fbx")
        Capture.objects.claim(first.pk, "slot-1")
        converted = Capture.objects.get(pk=first.pk)
        converted.converted.name = "derived/x/take.npz"  # as the conversion leaves it
        self.assertEqual(converted.next_in_line(), second)
