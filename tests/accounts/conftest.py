"""The account tests share the service tests' personas (``tests.segmentation.base``), their
cheap password hashing and their per-test media folder."""

from tests.segmentation.conftest import (  # noqa: F401
    _media_root_on_testcase,
    fast_password_hashing,
    media_root,
)
