"""The OpenAPI schema describes every answer, and the front end's API types are generated
from it: ``frontend/src/api/schema.d.ts`` must be what openapi-typescript makes of the
schema the serializers give now (``make frontend`` regenerates it)."""

import difflib
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FRONTEND = ROOT / "frontend"
CHECKED_IN = FRONTEND / "src" / "api" / "schema.d.ts"
GENERATOR = FRONTEND / "node_modules" / ".bin" / "openapi-typescript"


def export_schema(path):
    """``manage.py spectacular --validate --fail-on-warn``, in a process of its own so that
    no warning is hidden by one already reported in this one."""
    return subprocess.run(
        [sys.executable, "manage.py", "spectacular", "--validate", "--fail-on-warn", "--file", str(path)],
        cwd=ROOT, capture_output=True, text=True, timeout=300,
    )


@pytest.fixture(scope="module")
def schema(tmp_path_factory):
    path = tmp_path_factory.mktemp("openapi") / "openapi.yml"
    result = export_schema(path)
    assert result.returncode == 0, f"manage.py spectacular failed:\n{result.stdout}\n{result.stderr}"
    return path, result


def test_it_describes_every_operation_without_warnings_or_errors(schema):
    _, result = schema
    output = result.stdout + result.stderr
    assert "Warning" not in output and "Error" not in output, output


def test_it_keeps_the_checked_in_front_end_types_equal_to_the_generated_ones(schema, tmp_path):
    if not GENERATOR.exists():
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"{GENERATOR} is missing: `make frontend` installs it")
        pytest.skip(f"{GENERATOR} is missing: `make frontend` installs it")
    generated = tmp_path / "schema.d.ts"
    result = subprocess.run([str(GENERATOR), str(schema[0]), "--output", str(generated)],
                            cwd=FRONTEND, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    want, have = generated.read_text(), CHECKED_IN.read_text()
    diff = "".join(difflib.unified_diff(have.splitlines(True), want.splitlines(True),
                                        "checked in", "generated now", n=1))
    assert want == have, (
        f"{CHECKED_IN.relative_to(ROOT)} differs from the types of the current schema; "
        f"run `make frontend` and commit the file:\n{diff[:4000]}")
