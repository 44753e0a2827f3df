"""Stored files answered in byte ranges (RFC 9110 §14), as a ``<video>`` element asks
for them: it reads the file's end for the index, then seeks by asking for the bytes it
needs.

A range left open (``bytes=N-``, what a browser sends first) is answered with at most
``MAX_RANGE_BYTES``: the browser asks for the rest as it plays, and no request holds a web
worker for the whole length of a large file. Several ranges in one request (which no
browser sends for media) get the first one only.
"""

import re

from django.http import HttpResponse, StreamingHttpResponse

MAX_RANGE_BYTES = 4 * 1024 * 1024
CHUNK_BYTES = 256 * 1024
RANGE = re.compile(r"^bytes=(\d*)-(\d*)(?:,.*)?$")


def ranged_response(fieldfile, size, content_type, range_header, etag):
    """The stored file ``fieldfile`` (``size`` bytes): 206 with the asked range, 200 with
    all of it when no (usable) range was asked, 416 when the range lies past its end."""
    span = parse_range(range_header, size)
    if span == "unsatisfiable":
        response = HttpResponse(status=416)
        response["Content-Range"] = f"bytes */{size}"
        return _common(response, etag)
    start, stop = span if span else (0, size)
    response = StreamingHttpResponse(_read(fieldfile, start, stop), content_type=content_type,
                                     status=206 if span else 200)
    response["Content-Length"] = str(stop - start)
    if span:
        response["Content-Range"] = f"bytes {start}-{stop - 1}/{size}"
    return _common(response, etag)


def parse_range(header, size):
    """``(start, stop)`` (stop exclusive) of a ``Range`` header against a file of ``size``
    bytes, None when there is no range to honour, or ``"unsatisfiable"``."""
    match = RANGE.match((header or "").strip())
    if not match or (not match[1] and not match[2]):
        return None
    if not match[1]:  # the last N bytes
        length = min(int(match[2]), size)
        return (size - length, size) if length else "unsatisfiable"
    start = int(match[1])
    if start >= size:
        return "unsatisfiable"
    stop = size if not match[2] else min(int(match[2]) + 1, size)
    if stop <= start:
        return None  # last < first: a syntactically invalid range, ignored
    return start, min(stop, start + MAX_RANGE_BYTES)


def _read(fieldfile, start, stop):
    with fieldfile.storage.open(fieldfile.name, "rb") as handle:
        handle.seek(start)
        left = stop - start
        while left > 0:
            chunk = handle.read(min(CHUNK_BYTES, left))
            if not chunk:
                return
            left -= len(chunk)
            yield chunk


def _common(response, etag):
    response["Accept-Ranges"] = "bytes"
    response["ETag"] = f'"{etag}"'
    # Only members may fetch it: shared caches must not keep it.
    response["Cache-Control"] = "private, max-age=3600"
    response["X-Content-Type-Options"] = "nosniff"
    return response
