"""The service's domain errors, all under :class:`CutroomError`.

``segmentation.api.common.errors`` turns them (and motionlib's ``MotionlibError``) into HTTP, and
the job runner's guard (``services.jobs.guard``) stores their message on the failed job. Anything
else raised is a bug: both boundaries log it with its traceback and answer with an
internal error and a reference to quote, never with the exception's text as the user's fault.

Anything that is the caller's fault is an :class:`Invalid` (a ``ValueError``) whose message
starts with the field at fault, ``"field: what is wrong, got value"``: a 400.
"""

import logging
import secrets

log = logging.getLogger(__name__)


class CutroomError(Exception):
    """Base of every error the service raises on purpose."""


class Invalid(CutroomError, ValueError):
    """The caller's input cannot be used (a 400); the message names the field and value."""


class UploadError(Invalid):
    """An upload that cannot become a capture (wrong extension, empty, missing ASF…)."""


class UploadTooLarge(UploadError):
    """The upload exceeds ``CUTROOM_MAX_UPLOAD_MB``."""


class QuotaExceeded(UploadError):
    """The upload would take a project or user past a storage quota (a 413)."""


class TooManyRequests(Invalid):
    """A rate or concurrency limit (a 429); ``retry_after`` is in seconds."""

    def __init__(self, message, retry_after):
        super().__init__(message)
        self.retry_after = retry_after


class NotReady(Invalid):
    """The capture has no parsed data yet (queued, processing or failed)."""


class ReviewClosed(Invalid):
    """The review was submitted and takes no more edits."""


class ReviewStarted(Invalid):
    """Someone started reviewing the capture, so its candidates can no longer change."""


class ExportFormatError(Invalid):
    """An export format the library does not write."""


class ImportProblem(Invalid):
    """A file that cannot be imported; the message names the file and what is wrong."""


class StaleVersion(CutroomError):
    """A review write was based on an old version; ``review`` is the current one (a 409)."""

    def __init__(self, review):
        super().__init__(
            f"review {review.pk} is at version {review.version}; reload it and redo the change"
        )
        self.review = review


class StaleGold(CutroomError):
    """A gold version was saved from an old version; ``adjudication`` is the current one
    (a 409)."""

    def __init__(self, adjudication):
        super().__init__(
            f"the gold version is at version {adjudication.version}; reload it and redo the change"
        )
        self.adjudication = adjudication


class NotAllowed(CutroomError, PermissionError):
    """The caller's role does not allow the action: a 403 whose text says who may."""


class Missing(CutroomError, LookupError):
    """No such record among those the caller may see: a 404 (never a 403, which would say
    that it exists)."""


def internal_error(what, logger=log):
    """Log the exception being handled with its traceback and a short reference, and
    return the reference: the user quotes it, the administrators find the traceback."""
    reference = secrets.token_hex(4)
    logger.exception("%s failed with an internal error (reference %s)", what, reference)
    return reference
