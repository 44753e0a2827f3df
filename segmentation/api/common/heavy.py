"""Heavy answers that never change: built once per process, revalidated by ETag, and only a
few built at once, so the light requests of other users never queue behind them.

A capture's frames and a finished run's signals are written once (ingest, detection) and
never rewritten: an answer built from them is the same for every reader of that capture.
Twenty people opening a one-hour take ask for the same first chunk of frames and the same
signal; building each of those (reading the stored arrays, turning them into JSON) costs
tens to hundreds of milliseconds of CPU, which under the GIL and on a small machine is
what made everyone else's small requests wait.

So, per process:

- :class:`AnswerCache` keeps the rendered bytes of such answers (least recently used out
  first, ``CUTROOM_ANSWER_CACHE_MB`` in all). Identical requests that arrive together wait
  for the one build instead of each building their own.
- At most ``CUTROOM_HEAVY_REQUESTS`` builds run at once (:func:`heavy_slot`). A request
  waiting for a slot sleeps on a lock, which holds neither the GIL nor a CPU, so the
  web server's other threads keep answering light requests.
- Every answer carries an ETag (a hash of its bytes) and ``Cache-Control: private,
  no-cache``: the browser keeps the answer and asks again with ``If-None-Match``, which
  costs a permission check and a 304. Not ``immutable``: the URL names no format
  version, so an answer whose encoding changes with a new release must not outlive it in
  the browser; the hash of the bytes changes with the encoding, so the ETag does too.

The permission check runs on every request, before the cache is consulted.
"""

import hashlib
import threading
from collections import OrderedDict
from functools import wraps

from django.conf import settings
from django.http import HttpResponse, HttpResponseNotModified
from rest_framework.response import Response

from segmentation.errors import TooManyRequests

CACHE_CONTROL = "private, no-cache"

_slots_lock = threading.Lock()
_slots = {}  # limit -> BoundedSemaphore; one per configured limit (tests change it)


class heavy_slot:
    """Context manager: hold one of the process's ``CUTROOM_HEAVY_REQUESTS`` build slots.

    Waits at most ``CUTROOM_HEAVY_WAIT`` seconds, then raises :class:`TooManyRequests`
    (a 429 with Retry-After). A limit of 0 means no limit.
    """

    def __enter__(self):
        limit = settings.CUTROOM_HEAVY_REQUESTS
        self.slots = semaphore(limit) if limit else None
        if self.slots and not self.slots.acquire(timeout=settings.CUTROOM_HEAVY_WAIT):
            self.slots = None
            raise TooManyRequests(
                f"the server is busy building {limit} other large answers "
                "(CUTROOM_HEAVY_REQUESTS); try again in a few seconds", retry_after=5)
        return self

    def __exit__(self, *exc):
        if self.slots:
            self.slots.release()


def semaphore(limit):
    with _slots_lock:
        return _slots.setdefault(limit, threading.BoundedSemaphore(limit))


class Answer:
    """A rendered answer: bytes, content type and ETag."""

    __slots__ = ("content", "content_type", "etag")

    def __init__(self, content, content_type):
        self.content, self.content_type = content, content_type
        self.etag = '"' + hashlib.blake2b(content, digest_size=12).hexdigest() + '"'

    def response(self, request):
        if self.etag in _tags(request.META.get("HTTP_IF_NONE_MATCH", "")):
            response = HttpResponseNotModified()
        else:
            response = HttpResponse(self.content, content_type=self.content_type)
        response["ETag"] = self.etag
        response["Cache-Control"] = CACHE_CONTROL
        return response


def _tags(header):
    return {tag.strip().removeprefix("W/") for tag in header.split(",") if tag.strip()}


class AnswerCache:
    """Rendered answers by key, least recently used dropped first beyond ``max_bytes``.

    ``get_or_build(key, build)`` builds a missing answer once, however many threads ask
    for it together; ``build()`` returns an :class:`Answer`, or any other response, which
    is handed back and not kept.
    """

    def __init__(self, max_bytes):
        self.max_bytes, self.size = max_bytes, 0
        self.answers = OrderedDict()
        self.lock = threading.Lock()
        self.building = {}  # key -> Lock held by the thread building it

    def get(self, key):
        with self.lock:
            answer = self.answers.get(key)
            if answer is not None:
                self.answers.move_to_end(key)
            return answer

    def put(self, key, answer):
        if len(answer.content) > self.max_bytes:
            return
        with self.lock:
            old = self.answers.pop(key, None)
            self.size += len(answer.content) - (len(old.content) if old else 0)
            self.answers[key] = answer
            while self.size > self.max_bytes:
                _, dropped = self.answers.popitem(last=False)
                self.size -= len(dropped.content)

    def get_or_build(self, key, build):
        answer = self.get(key)
        if answer is not None:
            return answer
        with self.lock:
            building = self.building.setdefault(key, threading.Lock())
        with building:  # the first thread builds; the others wait here, then find it
            try:
                answer = self.get(key)
                if answer is None:
                    answer = build()
                    if isinstance(answer, Answer):
                        self.put(key, answer)
            finally:
                with self.lock:
                    self.building.pop(key, None)
        return answer

    def clear(self):
        with self.lock:
            self.answers.clear()
            self.size = 0


_cache = None
_cache_lock = threading.Lock()


def answer_cache():
    """This process's cache, sized by ``CUTROOM_ANSWER_CACHE_MB`` when first used."""
    global _cache
    with _cache_lock:
        if _cache is None:
            _cache = AnswerCache(settings.CUTROOM_ANSWER_CACHE_MB * 2**20)
        return _cache


def immutable(identity):
    """Decorate a DRF action whose answer depends only on the request's path and query and
    on stored data that never changes once written.

    ``identity(view, request)`` checks permission (raising as the action would) and
    returns what names that stored data (e.g. a run's id and its signals file), or None
    when the answer may still change: then it is built every time, still under a
    :func:`heavy_slot`.
    """

    def decorate(action):
        @wraps(action)
        def wrapper(view, request, *args, **kwargs):
            def build():
                with heavy_slot():
                    response = action(view, request, *args, **kwargs)
                    return _rendered(view, request, response)

            stored = identity(view, request)
            if stored is None or not settings.CUTROOM_ANSWER_CACHE_MB:
                answer = build()
            else:
                key = (action.__name__, stored, request.get_full_path(),
                       request.accepted_renderer.media_type)
                answer = answer_cache().get_or_build(key, build)
            return answer.response(request) if isinstance(answer, Answer) else answer

        return wrapper

    return decorate


def _rendered(view, request, response):
    """An :class:`Answer` of a successful response, else the response itself (errors and
    streams are passed on, never cached)."""
    if isinstance(response, Response):
        response = view.finalize_response(request, response)
        response.render()
    if response.status_code != 200 or response.streaming:
        return response
    return Answer(response.content, response["Content-Type"])
