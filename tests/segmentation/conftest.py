import pytest
from django.test import override_settings


@pytest.fixture(scope="session", autouse=True)
def fast_password_hashing():
    """Each persona's password is hashed once per test class; keep that cheap."""
    fast = override_settings(PASSWORD_HASHERS=["django.contrib.auth.hashers.MD5PasswordHasher"])
    fast.enable()
    yield
    fast.disable()


@pytest.fixture(autouse=True)
def media_root(settings, tmp_path):
    """Each test stores uploads and derived arrays in its own folder."""
    settings.MEDIA_ROOT = tmp_path / "media"
    return settings.MEDIA_ROOT


@pytest.fixture(autouse=True)
def _media_root_on_testcase(request, media_root):
    # unittest-style test cases reach the per-test folder as self.media_root.
    if request.instance is not None:
        request.instance.media_root = media_root
