"""Two lanes per web process, so that many people opening a long take never slow down
everyone else's requests.

A review page of a one-hour take makes requests that each cost tens of milliseconds of
CPU (its review of hundreds of segments, their label suggestions, the signals, the
frames); twenty people opening it at once make a hundred and forty of them. Under the
GIL a request's time grows with the number of threads of its process that want the CPU,
so a small capture's requests, a few milliseconds alone, would wait behind all of them.

So each read (GET, HEAD) is put in one of two lanes before any of its work is done:

- the *bulk* lane: a read about a capture of at least ``CUTROOM_LARGE_TAKE_FRAMES``
  frames (``/api/captures/<id>/…``), and any read of a client (its token, session or
  address) that made such a read in the last ``CUTROOM_BULK_LINGER`` seconds (the same
  page's ``/api/me/`` and ``/api/projects/``);
- the *light* lane: everything else, and every write: a person editing a long take is
  working, not browsing, and an edit costs only the rows it changes.

At most ``CUTROOM_BULK_REQUESTS`` bulk requests run at once per process; the others
wait on a lock, which holds neither the GIL nor a CPU, in arrival order. Light
requests never wait for a slot, so they share their process with at most that many
bulk requests. A process holds at most ``CUTROOM_BULK_QUEUE`` bulk requests (waiting,
running or handed on; fewer than its threads, so a light request always finds a free
thread), at most ``CUTROOM_BULK_PER_CLIENT`` of them from one client (so one client
cannot take every place); one more, or one that waited ``CUTROOM_HEAVY_WAIT`` seconds,
gets a 429 with Retry-After.

Where the bulk lane runs. ``make up`` starts a web server of its own for it, at a lower
CPU priority (``nice``), on a Unix socket (``CUTROOM_BULK_SOCKET``), and the main web
server's processes hand each bulk read to it before Django sees it (:class:`LaneDispatcher`,
the WSGI application of ``cutroom/wsgi.py``) and wait for its answer on the socket, which
costs them no CPU: on a busy machine the operating system
then gives the light requests the CPU first, whatever the bulk lane is doing; on an idle
one the bulk lane has all of it. Without that server (not configured, not running) a
process serves its bulk requests itself, still at most ``CUTROOM_BULK_REQUESTS`` at once.

Which lane a request is in decides only when it runs, never whether it is allowed:
permissions are checked by the view as always. The client key is a hash of the
``Authorization`` header or session cookie as sent, or of the address when there is
neither; a client that sends someone else's credentials only moves that key's requests.
"""

import hashlib
import hmac
import http.client
import logging
import re
import socket
import threading
import time
from collections import OrderedDict
from urllib.parse import quote

from django.conf import settings
from django.db import close_old_connections
from django.http import JsonResponse
from django.http.cookie import parse_cookie

logger = logging.getLogger(__name__)

CAPTURE_PATH = re.compile(r"^/api/captures/(\d+)/")

# Captures' frame counts, by id: written at ingest and never changed after.
_frames_lock = threading.Lock()
_frames = OrderedDict()
_FRAMES_KEPT = 4096


def capture_frames(capture_id):
    """The capture's frame count, or None (unknown id, or not ingested yet)."""
    with _frames_lock:
        if capture_id in _frames:
            _frames.move_to_end(capture_id)
            return _frames[capture_id]
    from segmentation.models import Capture

    n = Capture.objects.filter(pk=capture_id).values_list("n_frames", flat=True).first()
    if n is not None:  # a capture still ingesting may become large: ask again next time
        with _frames_lock:
            _frames[capture_id] = n
            while len(_frames) > _FRAMES_KEPT:
                _frames.popitem(last=False)
    return n


def client_key(meta):
    """Who is asking, as far as scheduling goes (``request.META`` or a WSGI environ)."""
    session = parse_cookie(meta.get("HTTP_COOKIE", "")).get(settings.SESSION_COOKIE_NAME)
    who = meta.get("HTTP_AUTHORIZATION") or session or meta.get("REMOTE_ADDR", "")
    return hashlib.blake2b(who.encode(), digest_size=8).digest()


class Lanes:
    """One process's bulk lane: its slots, the bulk requests it has in hand (in all and per
    client) and its lingering clients."""

    def __init__(self, slots):
        self.size, self.slots = slots, threading.Semaphore(slots)
        self.lock = threading.Lock()
        self.in_hand = 0
        self.per_client = {}  # client key -> bulk requests of it in hand
        self.bulk_until = {}  # client key -> monotonic time its requests stay bulk

    def is_bulk(self, path, key, now):
        match = CAPTURE_PATH.match(path)
        large = False
        if match:
            n = capture_frames(int(match.group(1)))
            large = n is not None and n >= settings.CUTROOM_LARGE_TAKE_FRAMES
        with self.lock:
            if large:
                self.bulk_until[key] = now + settings.CUTROOM_BULK_LINGER
                if len(self.bulk_until) > 10_000:
                    self.bulk_until = {k: t for k, t in self.bulk_until.items() if t > now}
                return True
            until = self.bulk_until.get(key)
            return until is not None and until > now

    def admit(self, key):
        """Count a bulk request in (waiting, running or handed on); False when this process
        has ``CUTROOM_BULK_QUEUE`` of them in hand, or the client
        ``CUTROOM_BULK_PER_CLIENT``: a thread is kept for light requests, and one client
        cannot take every place."""
        with self.lock:
            mine = self.per_client.get(key, 0)
            if self.in_hand >= settings.CUTROOM_BULK_QUEUE or mine >= settings.CUTROOM_BULK_PER_CLIENT:
                return False
            self.in_hand += 1
            self.per_client[key] = mine + 1
            return True

    def release(self, key):
        with self.lock:
            self.in_hand -= 1
            mine = self.per_client.pop(key) - 1
            if mine:
                self.per_client[key] = mine

    def enter(self):
        """Take a bulk slot; False after ``CUTROOM_HEAVY_WAIT`` seconds."""
        return self.slots.acquire(timeout=settings.CUTROOM_HEAVY_WAIT)

    def leave(self):
        self.slots.release()


_lanes = None
_lanes_lock = threading.Lock()


def lanes():
    """This process's lanes (made anew if ``CUTROOM_BULK_REQUESTS`` changed)."""
    global _lanes
    with _lanes_lock:
        if _lanes is None or _lanes.size != settings.CUTROOM_BULK_REQUESTS:
            _lanes = Lanes(settings.CUTROOM_BULK_REQUESTS)
        return _lanes


def busy():
    response = JsonResponse(
        {"detail": "the server is busy with other requests about long takes "
                   "(CUTROOM_BULK_QUEUE, CUTROOM_BULK_PER_CLIENT); try again in a few seconds"},
        status=429)
    response["Retry-After"] = "5"
    return response


# Headers the main server adds to a request it hands on: proof that it did (an HMAC of the
# SECRET_KEY), and the address the request came from.
LANE_HEADER, ADDRESS_HEADER = "X-Cutroom-Lane", "X-Cutroom-Client-Address"
# Hop-by-hop headers (RFC 9110 7.6.1) are never handed on, in either direction.
HOP_BY_HOP = {"connection", "keep-alive", "proxy-authenticate", "proxy-authorization", "te",
              "trailer", "transfer-encoding", "upgrade", "content-length"}
# An answer without a length, or longer than this, is streamed through rather than read whole.
STREAM_ABOVE = 8 * 2**20


def lane_proof():
    return hmac.new(settings.SECRET_KEY.encode(), b"cutroom bulk lane", "sha256").hexdigest()


class UnixConnection(http.client.HTTPConnection):
    def __init__(self, path, timeout):
        super().__init__("localhost", timeout=timeout)
        self.socket_path = path

    def connect(self):
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.settimeout(self.timeout)
        try:
            sock.connect(self.socket_path)
        except OSError:
            sock.close()
            raise
        self.sock = sock


class Unreachable(Exception):
    """The bulk server did not take the request: serve it here."""


class Upstream:
    """The bulk server on ``path``: one kept-alive connection per thread."""

    def __init__(self, path, timeout):
        self.path, self.timeout = path, timeout
        self.local = threading.local()

    def connection(self, fresh=False):
        conn = getattr(self.local, "conn", None)
        if conn is None or fresh:
            if conn is not None:
                conn.close()
            conn = self.local.conn = UnixConnection(self.path, self.timeout)
        return conn

    def forward(self, environ):
        """The bulk server's answer to the read in ``environ``: (status line, headers, body
        iterable); :class:`Unreachable` if it gave none (over a kept-alive connection, then
        once more over a new one, since the server may have closed the first while idle)."""
        target, headers = _target(environ), _request_headers(environ)
        for attempt in range(2):
            conn = self.connection(fresh=attempt > 0)
            try:
                conn.request(environ["REQUEST_METHOD"], target, headers=headers)
                upstream = conn.getresponse()
            except OSError as exc:  # not running, closed while idle, or died answering
                self.local.conn = None
                conn.close()
                if attempt == 0 and not isinstance(exc, (ConnectionRefusedError, FileNotFoundError)):
                    continue
                raise Unreachable(str(exc)) from exc
            return self.answer(upstream)
        raise Unreachable("no answer")

    def answer(self, upstream):
        headers = [(name, value) for name, value in upstream.getheaders()
                   if name.lower() not in HOP_BY_HOP]
        length = upstream.getheader("Content-Length")
        if length is not None and int(length) <= STREAM_ABOVE:
            body = [upstream.read()]
            headers.append(("Content-Length", length))
        else:  # this connection belongs to the stream until it ends
            self.local.conn = None
            body = _chunks(upstream)
        return f"{upstream.status} {upstream.reason}", headers, body


def _chunks(upstream):
    try:
        while chunk := upstream.read(2**16):
            yield chunk
    finally:
        upstream.close()


def _target(environ):
    """The request target as the client sent it."""
    raw = environ.get("RAW_URI")  # gunicorn's
    if raw:
        return raw
    path = quote((environ.get("SCRIPT_NAME", "") + environ.get("PATH_INFO", "")).encode("latin-1"))
    query = environ.get("QUERY_STRING")
    return f"{path}?{query}" if query else path


def _request_headers(environ):
    headers = {}
    for key, value in environ.items():
        if key.startswith("HTTP_"):
            name = key[5:].replace("_", "-").title()
            if name.lower() not in HOP_BY_HOP and not name.lower().startswith("x-cutroom-"):
                headers[name] = value
    if environ.get("CONTENT_TYPE"):
        headers["Content-Type"] = environ["CONTENT_TYPE"]
    headers[LANE_HEADER] = lane_proof()
    headers[ADDRESS_HEADER] = environ.get("REMOTE_ADDR", "")
    return headers


_upstream = None


def upstream():
    """The configured bulk server, or None."""
    global _upstream
    path = settings.CUTROOM_BULK_SOCKET
    if not path:
        return None
    with _lanes_lock:
        if _upstream is None or _upstream.path != path:
            _upstream = Upstream(path, timeout=settings.CUTROOM_BULK_TIMEOUT)
        return _upstream


PROOF_KEY = "HTTP_" + LANE_HEADER.upper().replace("-", "_")
ADDRESS_KEY = "HTTP_" + ADDRESS_HEADER.upper().replace("-", "_")
# The dispatcher's choice for a request it passes to Django, (bulk, client key), so that
# the middleware does not choose again.
CHOICE_KEY = "cutroom.lane"


def _proven(environ):
    """Whether the request carries the web server's proof that it handed it on."""
    proof = environ.get(PROOF_KEY)
    return proof is not None and hmac.compare_digest(proof, lane_proof())


def _bulk_read(environ):
    return (settings.CUTROOM_BULK_REQUESTS and environ.get("REQUEST_METHOD") in ("GET", "HEAD")
            and environ.get("PATH_INFO", "").startswith("/api/"))


class LaneDispatcher:
    """WSGI: hands bulk reads to the bulk lane's server before Django sees them, so that a
    request handed on costs this process only the copy of its answer; everything else,
    and whatever it could not hand on, goes to ``app``."""

    def __init__(self, app):
        self.app = app
        self.warned = False

    def __call__(self, environ, start_response):
        server = upstream()
        if server is None or not _bulk_read(environ) or _proven(environ):
            return self.app(environ, start_response)
        try:
            lane, key = lanes(), client_key(environ)
            bulk = lane.is_bulk(environ["PATH_INFO"], key, time.monotonic())
        except Exception:  # the database unreachable, say: Django answers, as for any request
            logger.exception("could not choose a lane for %s", environ.get("PATH_INFO"))
            return self.app(environ, start_response)
        environ[CHOICE_KEY] = (bulk, key)
        if not bulk:
            return self.app(environ, start_response)  # its request cycle closes old connections
        close_old_connections()  # outside Django's request cycle, as it does at the end of one
        if not lane.admit(key):
            return _wsgi_busy(start_response)
        try:
            status, headers, body = server.forward(environ)
        except Unreachable as exc:
            if not self.warned:
                logger.warning("bulk lane server at %s unreachable (%s): serving bulk "
                               "requests here", server.path, exc)
                self.warned = True
            return self.app(environ, start_response)  # served here, in this process's lane
        finally:
            lane.release(key)
        start_response(status, headers)
        return body


def _wsgi_busy(start_response):
    response = busy()
    start_response(f"{response.status_code} {response.reason_phrase}",
                   [*response.items(), ("Content-Length", str(len(response.content)))])
    return [response.content]


class LaneMiddleware:
    """Runs bulk reads (see the module docstring) at most ``CUTROOM_BULK_REQUESTS`` at a time
    in this process; off when that setting is 0. (Handing them to the bulk lane's server
    is :class:`LaneDispatcher`'s, before Django.)

    A request the web server handed on (it carries the proof) is served here, with the
    address it came from restored (throttles and logs go by it). A bulk read's answer says
    where it was served: ``X-Cutroom-Lane: bulk-server`` or ``bulk-here``.
    """

    def __init__(self, get_response):
        self.get_response = get_response

    def __call__(self, request):
        handed_on = self.handed_on(request)
        if not _bulk_read(request.META):
            return self.get_response(request)
        lane, choice = lanes(), request.META.get(CHOICE_KEY)
        if choice is None:
            key = client_key(request.META)
            bulk = handed_on or lane.is_bulk(request.path_info, key, time.monotonic())
        else:  # the dispatcher chose, then could not hand it on
            bulk, key = choice
        if not bulk:
            return self.get_response(request)
        if not lane.admit(key):
            return busy()
        try:
            if not lane.enter():
                return busy()
            try:
                response = self.get_response(request)
            finally:
                lane.leave()
        finally:
            lane.release(key)
        response[LANE_HEADER] = "bulk-server" if handed_on else "bulk-here"
        return response

    @staticmethod
    def handed_on(request):
        """Whether the web server handed this request on (then its address is restored)."""
        meta = request.META
        proven = _proven(meta)
        meta.pop(PROOF_KEY, None)
        address = meta.pop(ADDRESS_KEY, None)
        if proven:
            meta["REMOTE_ADDR"] = address or ""
        return proven
