"""The bulk lane (cutroom/lanes.py): requests about large takes, and their client's other
requests for a moment, run a few at a time or on a server of their own; other people's
requests never wait for them."""

import http.server
import json
import socketserver
import tempfile
import threading
import time
from pathlib import Path

from django.core.handlers.wsgi import WSGIHandler
from django.http import HttpResponse
from django.test import RequestFactory, override_settings

from accounts.models import ApiToken
from cutroom import lanes
from tests.segmentation.base import BaseTestCase

LARGE = 300


@override_settings(CUTROOM_LARGE_TAKE_FRAMES=LARGE, CUTROOM_BULK_REQUESTS=1,
                   CUTROOM_BULK_QUEUE=4, CUTROOM_BULK_SOCKET="", CUTROOM_HEAVY_WAIT=10)
class LaneTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        lanes._frames.clear()  # ids come back after a test's rollback
        lanes._lanes = None
        self.large = self.ready_capture(n_frames=LARGE + 100, name="long.bvh")
        self.small = self.ready_capture(n_frames=LARGE - 100, name="short.bvh")
        self.login(self.bob)

    def get(self, capture, who="Token bob", tail="review/"):
        return self.client.get(f"/api/captures/{capture.pk}/{tail}", HTTP_AUTHORIZATION=who)

    def hold_the_slot(self):
        lane = lanes.lanes()
        self.assertTrue(lane.enter())
        self.addCleanup(lane.leave)
        return lane


class LanesTestCase(LaneTestCase):
    def test_it_serves_a_request_about_a_large_take_in_the_bulk_lane(self):
        response = self.get(self.large)
        self.assertEqual(response.status_code, 200)
        self.assertEqual(response["X-Cutroom-Lane"], "bulk-here")

    def test_it_serves_a_request_about_a_small_take_in_the_light_lane(self):
        response = self.get(self.small)
        self.assertEqual(response.status_code, 200)
        self.assertNotIn("X-Cutroom-Lane", response)

    def test_it_keeps_that_clients_other_requests_in_the_bulk_lane_for_a_moment(self):
        self.get(self.large)
        self.assertEqual(self.client.get("/api/me/", HTTP_AUTHORIZATION="Token bob")["X-Cutroom-Lane"],
                         "bulk-here")
        self.assertEqual(self.get(self.small)["X-Cutroom-Lane"], "bulk-here")
        self.assertNotIn("X-Cutroom-Lane", self.get(self.small, who="Token rachel"))

    @override_settings(CUTROOM_BULK_LINGER=0)
    def test_it_lets_the_client_back_into_the_light_lane_after_the_linger(self):
        self.get(self.large)
        self.assertNotIn("X-Cutroom-Lane", self.get(self.small))

    def test_it_still_refuses_what_the_user_may_not_see(self):
        self.login(self.charlie)
        response = self.get(self.large, who="Token charlie")
        self.assertIn(response.status_code, (403, 404))
        self.assertEqual(response["X-Cutroom-Lane"], "bulk-here")

    def test_it_lets_a_light_request_through_while_the_bulk_slot_is_held(self):
        self.hold_the_slot()
        started = time.monotonic()
        self.assertEqual(self.get(self.small).status_code, 200)
        self.assertLess(time.monotonic() - started, 5)

    def through_the_middleware(self, capture):
        """The lane middleware around a view that touches no database (a thread of a
        test cannot share the test's transaction; the take's size is known beforehand)."""
        request = RequestFactory().get(f"/api/captures/{capture.pk}/review/",
                                       HTTP_AUTHORIZATION="Token bob")
        return lanes.LaneMiddleware(lambda r: HttpResponse("served"))(request)

    def test_it_serves_a_waiting_bulk_request_once_the_slot_is_free(self):
        lanes.capture_frames(self.large.pk)
        lane = lanes.lanes()
        self.assertTrue(lane.enter())
        got = []
        waiter = threading.Thread(target=lambda: got.append(self.through_the_middleware(self.large)))
        waiter.start()
        wait_until(lambda: lane.in_hand == 1)
        time.sleep(0.1)
        self.assertEqual(got, [])
        lane.leave()
        waiter.join(10)
        self.assertEqual(got[0].content, b"served")
        self.assertEqual(got[0]["X-Cutroom-Lane"], "bulk-here")

    @override_settings(CUTROOM_BULK_QUEUE=1)
    def test_it_answers_429_when_it_has_as_many_bulk_requests_in_hand_as_it_may(self):
        lanes.capture_frames(self.large.pk)
        lane = self.hold_the_slot()
        got = []
        waiter = threading.Thread(target=lambda: got.append(self.through_the_middleware(self.large)))
        waiter.start()
        wait_until(lambda: lane.in_hand == 1)
        response = self.get(self.large, who="Token rachel")
        lane.leave()
        waiter.join(10)
        self.assertEqual(response.status_code, 429)
        self.assertEqual(response["Retry-After"], "5")
        self.assertIn("CUTROOM_BULK_QUEUE", response.json()["detail"])
        self.assertEqual(got[0].content, b"served")
        lane.enter()  # given back by the cleanup
        # Another client's light request still goes through.
        self.login(self.alice)
        self.assertEqual(self.get(self.small, who="Token alice").status_code, 200)

    @override_settings(CUTROOM_BULK_PER_CLIENT=1)
    def test_it_answers_429_to_a_client_with_as_many_bulk_requests_in_hand_as_one_may(self):
        lane = lanes.lanes()
        bob = lanes.client_key(RequestFactory().get("/", HTTP_AUTHORIZATION="Token bob").META)
        self.assertTrue(lane.admit(bob))  # one of bob's is in hand
        self.addCleanup(lane.release, bob)
        refused = self.get(self.large)
        self.assertEqual(refused.status_code, 429)
        self.assertIn("CUTROOM_BULK_PER_CLIENT", refused.json()["detail"])
        self.login(self.rachel)
        self.assertEqual(self.get(self.large, who="Token rachel").status_code, 200)
        self.assertEqual(lane.in_hand, 1)  # rachel's was counted out again

    @override_settings(CUTROOM_BULK_REQUESTS=0)
    def test_it_has_no_bulk_lane_when_it_is_switched_off(self):
        self.assertNotIn("X-Cutroom-Lane", self.get(self.large))


class HandedOnTestCase(LaneTestCase):
    """A request the web server handed to the bulk lane's server."""

    def call(self, **headers):
        request = RequestFactory().get("/api/me/", REMOTE_ADDR="", **headers)
        return lanes.LaneMiddleware(lambda r: HttpResponse(r.META["REMOTE_ADDR"]))(request)

    def test_it_restores_the_address_the_request_came_from(self):
        response = self.call(HTTP_X_CUTROOM_LANE=lanes.lane_proof(),
                             HTTP_X_CUTROOM_CLIENT_ADDRESS="203.0.113.9")
        self.assertEqual(response.content, b"203.0.113.9")
        self.assertEqual(response["X-Cutroom-Lane"], "bulk-server")

    def test_it_ignores_an_address_without_the_proof(self):
        response = self.call(HTTP_X_CUTROOM_LANE="guessed",
                             HTTP_X_CUTROOM_CLIENT_ADDRESS="203.0.113.9")
        self.assertEqual(response.content, b"")
        self.assertNotIn("X-Cutroom-Lane", response)


class Recorder(http.server.BaseHTTPRequestHandler):
    """A bulk server on a Unix socket that answers with what it received."""

    protocol_version = "HTTP/1.1"

    def address_string(self):
        return "unix"

    def log_message(self, *args):
        pass

    def do_GET(self):
        self.answer()

    def answer(self):
        body = self.rfile.read(int(self.headers.get("Content-Length") or 0))
        seen = json.dumps({"method": self.command, "path": self.path,
                           "headers": dict(self.headers), "body": body.decode()}).encode()
        self.send_response(200)
        self.send_header("Content-Type", "application/json")
        self.send_header("ETag", '"abc"')
        self.send_header("Set-Cookie", "seen=1; Path=/")
        if self.path.endswith("chunked"):
            self.send_header("Transfer-Encoding", "chunked")
            self.end_headers()
            for part in (seen[:10], seen[10:]):
                self.wfile.write(b"%x\r\n%s\r\n" % (len(part), part))
            self.wfile.write(b"0\r\n\r\n")
        else:
            self.send_header("Content-Length", str(len(seen)))
            self.end_headers()
            self.wfile.write(seen)


class UnixServer(socketserver.ThreadingMixIn, socketserver.UnixStreamServer):
    daemon_threads = True


class ForwardingTestCase(LaneTestCase):
    """The web server's WSGI application hands bulk reads to the bulk lane's server."""

    def setUp(self):
        super().setUp()
        folder = Path(tempfile.mkdtemp())
        self.path = str(folder / "bulk.sock")
        self.server_requests = []
        seen = self.server_requests

        class Recording(Recorder):
            def answer(self):
                seen.append(self.path)
                super().answer()

        self.server = UnixServer(self.path, Recording)
        threading.Thread(target=self.server.serve_forever, daemon=True).start()
        self.addCleanup(self.server.server_close)
        self.addCleanup(self.server.shutdown)
        lanes._upstream = None
        _, self.key = ApiToken.objects.issue(self.bob)
        self.app = lanes.LaneDispatcher(WSGIHandler())

    def call(self, path, method="GET", body=None, **headers):
        """(status, headers, body, streamed) of ``path`` through the web server's application."""
        factory = RequestFactory()
        headers.setdefault("HTTP_AUTHORIZATION", f"Token {self.key}")
        if body is None:
            environ = factory.generic(method, path, **headers).environ
        else:
            environ = factory.generic(method, path, json.dumps(body), "application/json", **headers).environ
        got = {}

        def start_response(status, response_headers):
            got["status"], got["headers"] = int(status.split()[0]), response_headers

        with override_settings(CUTROOM_BULK_SOCKET=self.path):
            answer = self.app(environ, start_response)
            content = b"".join(answer)
        return got["status"], dict(got["headers"]), content, not isinstance(answer, list)

    def test_it_hands_a_bulk_read_to_the_bulk_server_with_its_headers(self):
        status, headers, body, _ = self.call(f"/api/captures/{self.large.pk}/review/?x=1",
                                                HTTP_IF_NONE_MATCH='"abc"')
        seen = json.loads(body)
        self.assertEqual(status, 200)
        self.assertEqual((seen["method"], seen["path"]), ("GET", f"/api/captures/{self.large.pk}/review/?x=1"))
        self.assertEqual(seen["headers"]["Authorization"], f"Token {self.key}")
        self.assertEqual(seen["headers"]["If-None-Match"], '"abc"')
        self.assertEqual(seen["headers"]["X-Cutroom-Lane"], lanes.lane_proof())
        self.assertEqual(seen["headers"]["X-Cutroom-Client-Address"], "127.0.0.1")
        self.assertEqual(headers["ETag"], '"abc"')
        self.assertEqual(headers["Set-Cookie"], "seen=1; Path=/")
        self.assertEqual(headers["Content-Length"], str(len(body)))

    def test_it_hands_on_a_bulk_read_that_claims_a_proof_it_does_not_have(self):
        # Else a client could have its reads of long takes served at the web server's priority.
        status, _, body, _ = self.call(f"/api/captures/{self.large.pk}/review/",
                                          HTTP_X_CUTROOM_LANE="guessed")
        self.assertEqual(status, 200)
        self.assertEqual(json.loads(body)["headers"]["X-Cutroom-Lane"], lanes.lane_proof())
        self.assertEqual(len(self.server_requests), 1)

    def test_it_serves_a_write_about_a_large_take_itself(self):
        status, headers, body, _ = self.call(f"/api/captures/{self.large.pk}/review/cuts/",
                                                method="POST", body={"frame": 50, "version": 1})
        self.assertEqual(status, 201)
        self.assertIn(50, [c["frame"] for c in json.loads(body)["cuts"]])
        self.assertNotIn("X-Cutroom-Lane", headers)
        self.assertEqual(self.server_requests, [])

    def test_it_counts_what_it_handed_on_against_its_limit(self):
        # Each read handed on holds one of the web server's threads while it waits.
        with override_settings(CUTROOM_BULK_QUEUE=0):
            status, headers, body, _ = self.call(f"/api/captures/{self.large.pk}/review/")
        self.assertEqual(status, 429)
        self.assertEqual(headers["Retry-After"], "5")
        self.assertIn("CUTROOM_BULK_QUEUE", json.loads(body)["detail"])
        self.assertEqual(self.server_requests, [])

    def test_it_streams_an_answer_of_unknown_length(self):
        status, headers, body, streamed = self.call(f"/api/captures/{self.large.pk}/chunked")
        self.assertTrue(streamed)
        self.assertNotIn("Transfer-Encoding", headers)  # the web server chunks it again itself
        self.assertEqual(json.loads(body)["method"], "GET")

    def test_it_hands_nothing_about_a_small_take_on(self):
        status, _, body, _ = self.call(f"/api/captures/{self.small.pk}/review/")
        self.assertEqual(status, 200)
        self.assertIn("cuts", json.loads(body))
        self.assertEqual(self.server_requests, [])

    def test_it_serves_the_bulk_read_itself_when_the_bulk_server_is_not_there(self):
        self.server.shutdown()
        self.server.server_close()
        Path(self.path).unlink()
        status, headers, body, _ = self.call(f"/api/captures/{self.large.pk}/review/")
        self.assertEqual(status, 200)
        self.assertEqual(headers["X-Cutroom-Lane"], "bulk-here")
        self.assertIn("cuts", json.loads(body))


def wait_until(predicate, timeout=10):
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError("condition not met")
        time.sleep(0.01)
