"""Point takes no capture can be (more points than joints allowed, values no take can
hold, nothing ever seen) are refused through the upload API with the file's own reason,
and a byte-order mark does not stop a valid one (issue 48, items 1, 8 and 12)."""

from tests.motionlib.points_data import points_file
from tests.segmentation.base import BaseTestCase


def markers_tsv(n_markers):
    names = [f"m{k}" for k in range(n_markers)]
    head = (f"NO_OF_FRAMES\t2\nFREQUENCY\t100\nNO_OF_MARKERS\t{n_markers}\n"
            "MARKER_NAMES\t" + "\t".join(names) + "\n")
    return (head + ("\t".join(["1.5"] * (3 * n_markers)) + "\n") * 2).encode()


class HostilePointUploadTest(BaseTestCase):
    def outcome(self, content, name):
        """The upload's answer: (status code, error text) of the request or, when it was
        accepted, of the capture once the worker's jobs ran."""
        self.login(self.alice)
        r = self.upload(content, name=name)
        if r.status_code != 201:
            return r.status_code, r.json()["detail"]
        capture = self.ingest(r.json()["id"])
        return capture.status, capture.error

    def assert_refused(self, content, name, reason):
        status, error = self.outcome(content, name)
        assert status in (400, "failed"), (status, error)
        assert reason in error, error
        assert "internal error" not in error

    def test_a_tsv_of_33334_markers(self):
        self.assert_refused(markers_tsv(33_334), "many.tsv",
                            "many.tsv:4: 33334 markers is more than the limit of 1000 joints")

    def test_a_coordinate_beyond_float32(self):
        self.assert_refused(b"frame,a_x,a_y,a_z,b_x,b_y,b_z\n0,1,2,3,4,5,6\n1,1,2,3,4,1e39,6\n",
                            "far.csv", "far.csv:3: column 6 ('b_y'): 1e+39 is beyond")

    def test_frame_number_1e19(self):
        self.assert_refused(b"frame,a_x,a_y,a_z,b_x,b_y,b_z\n0,1,2,3,4,5,6\n"
                            b"10000000000000000000,1,2,3,4,5,6\n", "late.csv",
                            "late.csv:3: column 1 (frame): frame 1e+19 is outside 0 to")

    def test_time_steps_of_1e300_frames_per_second(self):
        self.assert_refused(b"time,a_x,a_y,a_z,b_x,b_y,b_z\n0,1,2,3,4,5,6\n1e-300,1,2,3,4,5,6\n",
                            "fast.csv", "make 1e+300 frames per second")

    def test_a_take_in_which_nothing_is_ever_seen(self):
        self.assert_refused(b"frame,a_x,a_y,a_z,b_x,b_y,b_z\n0,,,,,,\n1,,,,,,\n2,,,,,,\n",
                            "blind.csv", "blind.csv: no point is seen in any of the 3 frames")

    def test_a_csv_with_a_byte_order_mark_is_ingested(self):
        content = b"\xef\xbb\xbf" + points_file("utkinect", "s01_e01.csv").read_bytes()
        status, error = self.outcome(content, "s01_e01.csv")
        assert status == "ready", error
