"""The error boundaries (the job guard, the API's translator) take only domain errors as the
caller's fault, so every error raised on purpose must be one: a bare ``ValueError`` raised
by our own code would be reported as an internal error instead of naming the bad value."""

import ast
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
BUILTIN = {"ValueError", "Exception"}  # a RuntimeError or TypeError says "bug" and may stay


def raised_builtins(package):
    """``path:line`` of each ``raise ValueError(...)`` (or a bare Exception) in a package."""
    found = []
    for path in sorted((REPO / package).rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            if isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call) \
                    and isinstance(node.exc.func, ast.Name) and node.exc.func.id in BUILTIN:
                found.append(f"{path.relative_to(REPO)}:{node.lineno}")
    return found


@pytest.mark.parametrize("package", ["motionlib", "segmentation"])
def test_it_raises_domain_errors_only(package):
    assert raised_builtins(package) == []

