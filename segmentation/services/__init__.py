"""Workflows of the service, one module per noun.

``do_*`` functions run under ``transaction.atomic`` and enqueue background work only
once their transaction commits, so a worker never sees a row that is not there yet. Every
kind of job (ingest, conversion, detection, training) runs through ``services.jobs``; all
of them are registered once this package is imported.
"""

from segmentation.services.captures import (
    default_method,
    detect_run,
    do_redetect,
    do_retry_capture,
    do_start_run,
    do_upload_capture,
    ingest_capture,
)
from segmentation.services.convert import convert_capture
from segmentation.services.invitations import (
    do_accept_invitation,
    do_add_member,
    do_cancel_invitation,
    do_decline_invitation,
)
from segmentation.services.projects import (
    do_add_label,
    do_create_project,
    do_set_member,
    do_update_project,
)
from segmentation.services.reviews import (
    do_change_cut,
    do_insert_cut,
    do_label_segment,
    do_submit_review,
    get_or_create_review,
    own_review,
)

__all__ = [
    "default_method",
    "convert_capture",
    "detect_run",
    "do_accept_invitation",
    "do_add_label",
    "do_add_member",
    "do_cancel_invitation",
    "do_change_cut",
    "do_create_project",
    "do_decline_invitation",
    "do_insert_cut",
    "do_redetect",
    "do_label_segment",
    "do_retry_capture",
    "do_set_member",
    "do_start_run",
    "do_submit_review",
    "do_update_project",
    "do_upload_capture",
    "get_or_create_review",
    "ingest_capture",
    "own_review",
]
