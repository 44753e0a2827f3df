"""motionlib is a plain numerical library: importing any of its modules imports neither
Django nor Blender's ``bpy`` (the FBX reader must import it only when it reads a file); it
ships no benchmark or tuning module; and no two of its modules import each other."""

import ast
import importlib.util
import pkgutil
import re
import subprocess
import sys
from pathlib import Path

from tests.graphs import cycles

# Runs in a fresh interpreter, so nothing this test process imported counts. It imports
# every module in turn and names the first one after which a forbidden package is loaded.
WALK = r"""
import importlib, pkgutil, sys

FORBIDDEN = ("django", "bpy")
motionlib = importlib.import_module("motionlib")
names = sorted(m.name for m in pkgutil.walk_packages(motionlib.__path__, "motionlib.")
               if not m.name.endswith(".__main__"))
for name in ["motionlib", *names]:
    importlib.import_module(name)
    loaded = [f for f in FORBIDDEN if f in sys.modules]
    if loaded:
        sys.exit(f"importing {name} imported {', '.join(loaded)}")
print("\n".join(names))
"""


def test_it_imports_every_motionlib_module_without_django_or_bpy():
    result = subprocess.run([sys.executable, "-c", WALK], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    # The walk reached the subpackages' modules, not only the top level.
    walked = set(result.stdout.split())
    assert {"motionlib.cli", "motionlib.io.bvh", "motionlib.segmenters.default"} <= walked


def motionlib_modules() -> list[str]:
    """Every module of the motionlib package as installed (importable), subpackages too."""
    import motionlib

    return ["motionlib", *sorted(m.name for m in pkgutil.walk_packages(motionlib.__path__,
                                                                          "motionlib."))]


def test_it_ships_no_benchmark_or_tuning_module():
    # The research apparatus lives in benchmarks/quality (not installed): no module of the
    # library is one, and none imports it.
    modules = motionlib_modules()
    apparatus = [name for name in modules if re.search(r"bench|tuning", name.rsplit(".")[-1])]
    assert apparatus == []
    importers = [name for name in modules
                 if any(target.split(".")[0] == "benchmarks"
                        for target in imported(name, set(modules)))]
    assert importers == []


def imported(name: str, known: set[str]) -> set[str]:
    """The modules ``name``'s source imports when it runs: every import statement, at
    module level or deferred inside a function (a deferred import is still a dependency;
    deferring it only hides a circle from the interpreter), but not those under ``if
    TYPE_CHECKING:``, which never run (they name types for annotations). ``from package
    import name`` counts as an import of the submodule when ``name`` is one of ``known``,
    else of the package; a package imported on the way to its submodule is not counted.
    Compiled modules import nothing of motionlib."""
    spec = importlib.util.find_spec(name)
    path, is_package = Path(spec.origin), spec.submodule_search_locations is not None
    if path.suffix != ".py":
        return set()
    found = set()
    for node in _run_nodes(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            package = (name if is_package else name.rpartition(".")[0]).split(".")
            base = package[:len(package) - node.level + 1] if node.level else []
            module = ".".join([*base, *([node.module] if node.module else [])])
            found.update(f"{module}.{alias.name}" if f"{module}.{alias.name}" in known
                         else module for alias in node.names)
    found.discard(name)
    return found


def _run_nodes(tree: ast.AST):
    """Every node of ``tree`` but those only type checkers see (``if TYPE_CHECKING:``)."""
    pending = [tree]
    while pending:
        node = pending.pop()
        yield node
        if isinstance(node, ast.If) and _type_checking(node.test):
            pending.extend(node.orelse)
        else:
            pending.extend(ast.iter_child_nodes(node))


def _type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or \
        (isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def test_no_two_motionlib_modules_import_each_other_even_through_others():
    modules = set(motionlib_modules())
    graph = {name: imported(name, modules) & modules for name in modules}
    assert cycles(graph) == []


def test_imports_only_type_checkers_see_are_not_counted(tmp_path, monkeypatch):
    (tmp_path / "typed_only.py").write_text(
        "from typing import TYPE_CHECKING\nimport json\n"
        "if TYPE_CHECKING:\n    import csv\nelse:\n    import os\n"
        "def late():\n    import re\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert imported("typed_only", set()) == {"typing", "json", "os", "re"}
