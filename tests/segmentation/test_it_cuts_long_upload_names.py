"""An upload's file name of more than about 1 KB (Django's multipart parser refused the
part's headers past 1,024 bytes) is accepted and cut to 255 characters keeping its
extension, as docs/operations.md promises; only a name past the bound on a part's headers
is refused, with a message saying so (issue 48, item 12)."""

from segmentation.api.common.parsers import MAX_PART_HEADER_BYTES
from segmentation.models import Capture
from tests.segmentation.base import BaseTestCase, synthetic_bvh

BOUNDARY = "----cutroom-test-boundary"


def multipart(project_id, name, content):
    """A multipart body as a browser sends it, with the file name as long as it is (the
    test client's own encoder cuts names to 255 characters first, as Django's files do)."""
    head = (f'--{BOUNDARY}\r\nContent-Disposition: form-data; name="project"\r\n\r\n'
            f'{project_id}\r\n--{BOUNDARY}\r\nContent-Disposition: form-data; name="file"; '
            f'filename="{name}"\r\nContent-Type: application/octet-stream\r\n\r\n')
    return head.encode() + content + f"\r\n--{BOUNDARY}--\r\n".encode()


class LongUploadNamesTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.bob)

    def upload(self, content, name="take.bvh", project=None, asf=None):
        return self.client.generic("POST", "/api/captures/", multipart(self.project.pk, name, content),
                                   content_type=f"multipart/form-data; boundary={BOUNDARY}")

    def test_a_name_of_over_a_kilobyte_is_cut_to_255_characters_keeping_its_extension(self):
        for seed, name in enumerate(("walk-" * 400 + ".bvh",  # 2,004 bytes
                                     "\u6b69\u884c" * 200 + ".bvh",  # 1,204 bytes of UTF-8
                                     "\U0001f3c3" * 255 + ".BVH")):  # 1,024 bytes
            with self.subTest(length=len(name.encode())):
                r = self.upload(synthetic_bvh(seed=seed + 10, duration=1.0), name=name)
                self.assertEqual(r.status_code, 201, r.content[:300])
                capture = Capture.objects.get(pk=r.json()["id"])
                self.assertEqual(len(capture.name), 255)
                self.assertEqual(capture.name[-4:].lower(), ".bvh")
                self.assertEqual(capture.name[:-4], name[:251])
                self.assertEqual(capture.format, "bvh")

    def test_a_name_past_the_bound_on_headers_is_refused_saying_so(self):
        name = "x" * MAX_PART_HEADER_BYTES + ".bvh"
        r = self.upload(synthetic_bvh(seed=20, duration=1.0), name=name)
        self.assertEqual(r.status_code, 400, r.content[:300])
        detail = r.json()["detail"]
        self.assertIn(f"file: the file's name is too long; a part's headers (its name with "
                      f"them) may hold at most {MAX_PART_HEADER_BYTES} bytes", detail)
        self.assertLess(len(detail), 400)
