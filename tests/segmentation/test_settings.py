import pytest

from cutroom.settings import envbool, envint, envlist


def test_it_reads_booleans(monkeypatch):
    monkeypatch.setenv("FLAG", "Yes")
    assert envbool("FLAG", False) is True
    monkeypatch.setenv("FLAG", "0")
    assert envbool("FLAG", True) is False


def test_it_uses_the_default_when_unset_or_empty(monkeypatch):
    monkeypatch.delenv("FLAG", raising=False)
    assert envbool("FLAG", True) is True
    monkeypatch.setenv("NUMBER", "")
    assert envint("NUMBER", 7) == 7


def test_it_names_the_variable_with_a_bad_value(monkeypatch):
    monkeypatch.setenv("FLAG", "maybe")
    with pytest.raises(ValueError, match="FLAG must be true or false, got 'maybe'"):
        envbool("FLAG", False)
    monkeypatch.setenv("NUMBER", "12MB")
    with pytest.raises(ValueError, match="NUMBER must be an integer, got '12MB'"):
        envint("NUMBER", 1)


def test_it_splits_lists(monkeypatch):
    monkeypatch.setenv("HOSTS", "a.example, b.example,")
    assert envlist("HOSTS", []) == ["a.example", "b.example"]


@pytest.mark.django_db
def test_the_checks_at_start_say_nothing_on_sqlite():
    """Regression: ``make up`` printed models.W040 on every start: SQLite keeps the library
    list's covering indexes without their INCLUDE columns (its own, migrations 0020
    and 0021, serve the list there), which is expected, not news."""
    import io

    from django.conf import settings
    from django.core.management import call_command

    if settings.DATABASES["default"]["ENGINE"] != "django.db.backends.sqlite3":
        pytest.skip("the warning is SQLite's")
    out, err = io.StringIO(), io.StringIO()
    call_command("check", databases=["default"], stdout=out, stderr=err)
    assert "W040" not in out.getvalue() + err.getvalue()
    assert "no issues" in out.getvalue()
