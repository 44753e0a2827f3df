"""Domain errors of the service. ``segmentation.api.errors`` turns them into HTTP.

Anything that is the caller's fault is a ``ValueError`` whose message names the field
and value at fault (like motionlib's ``CaptureError`` and ``ParamError``): a 400.
"""


class UploadError(ValueError):
    """An upload that cannot become a capture (wrong extension, empty, missing ASF…)."""


class UploadTooLarge(UploadError):
    """The upload exceeds ``CUTROOM_MAX_UPLOAD_MB``."""


class QuotaExceeded(UploadError):
    """The upload would take a project or user past a storage quota (a 413)."""


class TooManyRequests(ValueError):
    """A rate or concurrency limit (a 429); ``retry_after`` is in seconds."""

    def __init__(self, message, retry_after):
        super().__init__(message)
        self.retry_after = retry_after


class NotReady(ValueError):
    """The capture has no parsed data yet (queued, processing or failed)."""


class ReviewClosed(ValueError):
    """The review was submitted and takes no more edits."""


class StaleVersion(Exception):
    """A review write was based on an old version; ``review`` is the current one."""

    def __init__(self, review):
        super().__init__(
            f"review {review.pk} is at version {review.version}; reload it and redo the change"
        )
        self.review = review


class ReviewStarted(ValueError):
    """Someone started reviewing the capture, so its candidates can no longer change."""


class NotAllowed(PermissionError):
    """The caller's role does not allow the action: a 403 whose text says who may."""
