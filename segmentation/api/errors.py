"""The one translator from domain errors to HTTP responses.

- ``StaleVersion`` -> 409 with the current review;
- ``UploadTooLarge``, ``QuotaExceeded`` -> 413;
- ``NotAllowed`` (a role refusal on a project the caller sees) -> 403;
- ``TooManyRequests`` (rate and concurrency limits) -> 429 with ``Retry-After``;
- any other ``ValueError`` (motionlib's ``CaptureError``/``ParamError``, the service's
  own) -> 400 with its message, which names the field, file, line or value at fault;
- DRF's own errors keep their status, and always carry a readable ``detail``.
"""

import re

from django.http import Http404
from rest_framework import status
from rest_framework.exceptions import NotFound
from rest_framework.response import Response
from rest_framework.views import exception_handler as drf_exception_handler

from motionlib.segmenters import ParamError
from segmentation.errors import (
    NotAllowed,
    QuotaExceeded,
    StaleVersion,
    TooManyRequests,
    UploadTooLarge,
)

FIELD = re.compile(r"^(\w+): (.+)$", re.DOTALL)
NO_MATCH = re.compile(r"^No (\w+) matches the given query\.$")


def exception_handler(exc, context):
    if isinstance(exc, StaleVersion):
        from segmentation.api.serializers import ReviewSerializer

        body = {"detail": str(exc), "review": ReviewSerializer(exc.review).data}
        return Response(body, status=status.HTTP_409_CONFLICT)
    if isinstance(exc, NotAllowed):
        return Response({"detail": str(exc)}, status=status.HTTP_403_FORBIDDEN)
    if isinstance(exc, TooManyRequests):
        return Response(_value_error_body(exc), status=429,
                        headers={"Retry-After": str(exc.retry_after)})
    if isinstance(exc, ValueError):
        code = 413 if isinstance(exc, UploadTooLarge | QuotaExceeded) else 400
        return Response(_value_error_body(exc), status=code)
    if isinstance(exc, Http404):
        # Django's "No Cut matches the given query." names a model class, not a thing.
        found = NO_MATCH.match(str(exc))
        exc = NotFound(f"No such {_words(found.group(1))}." if found else "Not found.")
    response = drf_exception_handler(exc, context)
    if response is not None and isinstance(response.data, dict) and "detail" not in response.data:
        response.data = {"detail": _summary(response.data), **response.data}
    elif response is not None and isinstance(response.data, list):
        response.data = {"detail": _summary(response.data), "errors": response.data}
    return response


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
