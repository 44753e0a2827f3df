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


@pytest.fixture(autouse=True)
def similar_index_dir(settings, tmp_path):
    """Each test keeps its similar-clip indexes in its own folder, and no process cache
    of an index outlives the test (ids are reused once a test's rows are rolled back)."""
    from segmentation.similar import index

    settings.SIMILAR_INDEX_DIR = tmp_path / "similar"
    index.forget()
    yield settings.SIMILAR_INDEX_DIR
    index.forget()


@pytest.fixture(autouse=True)
def answer_cache():
    """No built frames or signals answer outlives its test (ids and file names recur once a
    test's rows and media folder are gone)."""
    from segmentation.api.common import heavy

    heavy.answer_cache().clear()
    yield heavy.answer_cache()
    heavy.answer_cache().clear()


@pytest.fixture
def up(tmp_path):
    """Start ``scripts/up.py`` (``Up``) on a fresh port; every one started is stopped after."""
    from tests.segmentation.test_command_up import Up, free_port

    started = []

    def start(*args, var=tmp_path / "var", env=None):
        started.append(Up(var, free_port(), *args, env=env))
        return started[-1]

    yield start
    for process in started:
        process.close()
