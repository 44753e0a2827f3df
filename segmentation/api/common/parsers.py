"""The one JSON parser of every API body.

Before a value reaches a serializer or a database driver it is held to what the service
can store and compute with, so that no body can turn into a 500:

- nesting at most ``MAX_DEPTH`` levels (no body of this API nests more than four; a
  deeper one would otherwise exhaust the decoder's recursion);
- integers within the 64-bit range of a database integer (a larger id, frame or
  parameter would overflow the driver or a float conversion);
- finite numbers only (``1e400`` decodes to infinity, ``NaN`` is not JSON).

The error is an ``Invalid`` (a 400) naming the top-level field at fault and where in it.

Multipart bodies (uploads) go through ``UploadParser``: Django's parser refuses a part
whose headers pass 1,024 bytes, and a file's name is in its part's headers, so a name of
255 characters of UTF-8 (up to 1,020 bytes) or a longer one (which Django then cuts to 255
characters, keeping the extension) was refused with a parser message. The bound on a
part's headers is ``MAX_PART_HEADER_BYTES`` instead; past it the refusal says why.
"""

import json
import math
import re

from django.conf import settings
from django.http import multipartparser
from rest_framework.exceptions import ParseError
from rest_framework.parsers import JSONParser, MultiPartParser

from segmentation.api.common.params import INT_RANGE
from segmentation.errors import Invalid

MAX_DEPTH = 16
# The bound on one multipart part's headers (Django's is 1,024 bytes): a file name of
# several kilobytes still fits, and a header is still bounded.
MAX_PART_HEADER_BYTES = 16 * 1024
# Django's parser reads the module's bound at each part; every multipart body this
# service reads (API uploads, admin forms) is held to this one.
multipartparser.MAX_TOTAL_HEADER_SIZE = MAX_PART_HEADER_BYTES
# A string (with its escapes) or a bracket: what the nesting scan must tell apart.
TOKENS = re.compile(r'"(?:[^"\\]|\\.)*"|[\[\]{}]', re.DOTALL)
KEY_AFTER = re.compile(r"\s*:")


class BoundedJSONParser(JSONParser):
    """DRF's JSON parser, refusing what ``check_body`` refuses."""

    def parse(self, stream, media_type=None, parser_context=None):
        parser_context = parser_context or {}
        encoding = parser_context.get("encoding", settings.DEFAULT_CHARSET)
        try:
            text = stream.read().decode(encoding)
        except UnicodeDecodeError as exc:
            raise ParseError(f"JSON parse error - the body is not {encoding} text: {exc}") from None
        check_nesting(text)
        try:
            data = json.loads(text, parse_constant=_not_a_number)
        except Invalid:
            raise
        except ValueError as exc:  # not JSON, or an integer of thousands of digits
            raise ParseError(f"JSON parse error - {exc}") from None
        check_values(data)
        return data


class UploadParser(MultiPartParser):
    """DRF's multipart parser, whose refusal of an overlong part header (a file name of
    more than ``MAX_PART_HEADER_BYTES``) names the field and the bound."""

    def parse(self, stream, media_type=None, parser_context=None):
        try:
            return super().parse(stream, media_type, parser_context)
        except ParseError as exc:
            if "header size" not in str(exc.detail):
                raise
            raise Invalid(f"file: the file's name is too long; a part's headers (its name with "
                          f"them) may hold at most {MAX_PART_HEADER_BYTES} bytes; rename the "
                          "file (names are kept to 255 characters anyway)") from None


def _not_a_number(name):
    raise Invalid(f"body: {name} is not a number JSON allows")


def check_nesting(text):
    """Refuse JSON text nested deeper than ``MAX_DEPTH``, naming the top-level field."""
    depth, field = 0, None
    for token in TOKENS.finditer(text):
        value = token.group()
        if value in "[{":
            depth += 1
            if depth > MAX_DEPTH:
                where = f"{field}: " if field else "body: "
                raise Invalid(f"{where}nested deeper than {MAX_DEPTH} levels (at character "
                              f"{token.start()}); no field of this API nests that deep")
        elif value in "]}":
            depth -= 1
        elif depth == 1 and KEY_AFTER.match(text, token.end()):
            field = value[1:-1]


def check_values(data, path=()):
    """Refuse integers beyond the 64-bit range and non-finite numbers anywhere in ``data``."""
    if isinstance(data, dict):
        for key, value in data.items():
            check_values(value, (*path, key))
    elif isinstance(data, list):
        for index, value in enumerate(data):
            check_values(value, (*path, index))
    elif isinstance(data, bool):
        return
    elif isinstance(data, int) and not INT_RANGE[0] <= data <= INT_RANGE[1]:
        raise Invalid(f"{_where(path)}{_digits(data)} is outside the integer range "
                      f"{INT_RANGE[0]}..{INT_RANGE[1]}")
    elif isinstance(data, float) and not math.isfinite(data):
        raise Invalid(f"{_where(path)}must be a finite number, got {data}")


def _where(path):
    """"captures: item 0 " for ("captures", 0), "params: x " for ("params", "x")."""
    if not path:
        return "body: "
    top, rest = path[0], path[1:]
    inside = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in rest).lstrip(".")
    return f"{top}: " + (f"{inside} = " if inside else "")


def _digits(value):
    """The integer as written, or its first digits and length (the decoder already refused
    more than a few thousand digits)."""
    text = str(value)
    return text if len(text) <= 40 else f"{text[:20]}... ({len(text)} digits)"
