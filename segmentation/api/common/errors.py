"""The one translator from domain errors to HTTP responses.

- ``StaleVersion`` -> 409 with the current review, ``StaleGold`` -> 409 with the current
  gold version;
- ``UploadTooLarge``, ``QuotaExceeded`` -> 413, and so is a body over
  ``DATA_UPLOAD_MAX_MEMORY_SIZE`` (Django's ``RequestDataTooBig``);
- ``NotAllowed`` (a role refusal on a project the caller sees) -> 403;
- ``Missing`` (no such record among those the caller sees) -> 404;
- ``TooManyRequests`` (rate and concurrency limits) -> 429 with ``Retry-After``;
- any other domain error (motionlib's ``MotionlibError``: ``CaptureError``, ``ParamError``…;
  the service's ``Invalid``) -> 400 with its message, which names the field, file, line or
  value at fault;
- DRF's own errors keep their status, and always carry a readable ``detail``;
- anything else is a bug, not the caller's fault (a bare ``ValueError`` from numpy too): it is
  logged with its traceback and answered 500 with a reference to quote.
"""

import logging
import re

from django.conf import settings
from django.core.exceptions import RequestDataTooBig
from django.http import Http404
from rest_framework import status
from rest_framework.exceptions import NotFound
from rest_framework.response import Response
from rest_framework.views import exception_handler as drf_exception_handler

from motionlib.errors import MotionlibError, ParamError
from segmentation.api.common.serializers.gold import StaleGoldSerializer, gold_body
from segmentation.api.common.serializers.reviews import ReviewSerializer
from segmentation.errors import (
    CutroomError,
    Missing,
    NotAllowed,
    QuotaExceeded,
    StaleGold,
    StaleVersion,
    TooManyRequests,
    UploadTooLarge,
    internal_error,
)

log = logging.getLogger(__name__)

FIELD = re.compile(r"^(\w+): (.+)$", re.DOTALL)
NO_MATCH = re.compile(r"^No (\w+) matches the given query\.$")


def exception_handler(exc, context):
    if isinstance(exc, MotionlibError | CutroomError):
        return _domain_response(exc)
    if isinstance(exc, RequestDataTooBig):
        return _too_big()
    if isinstance(exc, Http404):
        # Django's "No Cut matches the given query." names a model class, not a thing.
        found = NO_MATCH.match(str(exc))
        exc = NotFound(f"No such {_words(found.group(1))}." if found else "Not found.")
    response = drf_exception_handler(exc, context)
    if response is None:
        reference = internal_error(_what(context), log)
        return Response({"detail": "internal error", "reference": reference},
                        status=status.HTTP_500_INTERNAL_SERVER_ERROR)
    if isinstance(response.data, dict) and "detail" not in response.data:
        response.data = {"detail": _summary(response.data), **response.data}
    elif isinstance(response.data, list):
        response.data = {"detail": _summary(response.data), "errors": response.data}
    return response


def _too_big():
    limit = settings.DATA_UPLOAD_MAX_MEMORY_SIZE
    detail = (f"The request body is larger than {limit} bytes ({limit / 2**20:g} MB), the "
              "most a request other than a file upload may send.")
    return Response({"detail": detail}, status=status.HTTP_413_REQUEST_ENTITY_TOO_LARGE)


def _domain_response(exc):
    if isinstance(exc, StaleVersion):
        body = {"detail": str(exc), "review": ReviewSerializer(exc.review).data}
        return Response(body, status=status.HTTP_409_CONFLICT)
    if isinstance(exc, StaleGold):
        body = StaleGoldSerializer({"detail": str(exc), "gold": gold_body(exc.adjudication)}).data
        return Response(body, status=status.HTTP_409_CONFLICT)
    if isinstance(exc, NotAllowed):
        return Response({"detail": str(exc)}, status=status.HTTP_403_FORBIDDEN)
    if isinstance(exc, Missing):
        return Response({"detail": str(exc)}, status=status.HTTP_404_NOT_FOUND)
    if isinstance(exc, TooManyRequests):
        return Response(_value_error_body(exc), status=429,
                        headers={"Retry-After": str(exc.retry_after)})
    code = 413 if isinstance(exc, UploadTooLarge | QuotaExceeded) else 400
    return Response(_value_error_body(exc), status=code)


def _what(context):
    request = context.get("request")
    return f"{request.method} {request.path}" if request is not None else "a request"


def _value_error_body(exc):
    message = str(exc)
    body = {"detail": message}
    match = FIELD.match(message)
    if match:
        field, text = match.groups()
        if isinstance(exc, ParamError) and field != "method":
            body["params"] = {field: [text]}
        else:
            body[field] = [text]
    return body


def _summary(data):
    """One line out of DRF's nested field errors: "version: This field is required."."""
    if isinstance(data, dict):
        return "; ".join(f"{key}: {_summary(value)}" for key, value in data.items())
    if isinstance(data, list):
        return " ".join(_summary(item) for item in data)
    return str(data)


def _words(class_name):
    """"SegmentLabel" -> "segment label"."""
    return re.sub(r"(?<!^)(?=[A-Z])", " ", class_name).lower()
