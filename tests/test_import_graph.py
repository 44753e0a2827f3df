"""The import graph of the ``cutroom`` project package and the ``segmentation`` app has no
cycle, and the services do not depend on Celery.

The graph is read from the source with ``ast``, without importing anything. An edge goes
from a module to each module of the two packages it imports:

- every ``import`` statement counts, those inside functions too: a function-level import
  is still a dependency, only a deferred one, and deferring it is how a cycle hides;
- ``from package import name`` is an edge to the submodule ``package.name`` when there is
  one, else to ``package`` (the name is an attribute of its ``__init__``);
- the initialisation of a module's parent packages, which Python runs first, is not an
  edge (as in import-linter and grimp): a package ``__init__`` that re-exports its
  submodules would otherwise form a cycle with each of them;
- ``include("dotted.module")`` in a URL configuration is an edge: Django imports it.

Cycles are looked for at three granularities: modules; the app's parts (``api``,
``services``, ``models``, ``management``, and each other module of ``segmentation`` on
its own; ``cutroom.accounts``); and the two packages themselves, which may depend on each
other in one direction only (the project mounts the app, so the app never imports the
project).
"""

import ast
import collections
from pathlib import Path

from tests.graphs import cycles, package_modules, private_uses

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("cutroom", "segmentation")
PARTS = ("segmentation.api", "segmentation.services", "segmentation.models",
         "segmentation.management", "cutroom.accounts")


def modules():
    """{dotted name: source path} of the two packages (migrations left out)."""
    found = {}
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            if "migrations" in path.parts:
                continue
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            found[".".join(parts)] = path
    return found


def imported_names(tree, module, is_package, known=None):
    """The dotted names a module's source imports, at any depth of its code. With
    ``known`` (module names), ``from package import name`` gives ``package.name`` when that
    is a known module, else ``package``."""
    here = module if is_package else module.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = here
                for _ in range(node.level - 1):
                    anchor = anchor.rpartition(".")[0]
                base = f"{anchor}.{base}" if base else anchor
            for alias in node.names:
                name = f"{base}.{alias.name}"
                yield name if known is None or name in known else base
        elif (isinstance(node, ast.Call) and getattr(node.func, "id", "") == "include"
              and node.args and isinstance(node.args[0], ast.Constant)
              and isinstance(node.args[0].value, str)):
            yield node.args[0].value


def import_graph():
    """{module: set of the two packages' modules it imports}."""
    known = modules()
    graph = {}
    for module, path in known.items():
        names = imported_names(ast.parse(path.read_text()), module, path.name == "__init__.py", known)
        graph[module] = {name for name in names if name in known} - {module}
    return graph


def coarsened(graph, group):
    """The graph between groups of modules (``group(module)`` names a module's group)."""
    coarse = collections.defaultdict(set)
    for module, edges in graph.items():
        coarse[group(module)]
        for target in edges:
            if group(target) != group(module):
                coarse[group(module)].add(group(target))
    return coarse


def part(module):
    return next((p for p in PARTS if module == p or module.startswith(p + ".")), module)


def describe(graph, found):
    return "; ".join(
        " ".join(f"{m} -> {sorted(graph[m] & set(component))}" for m in component)
        for component in found
    )


def test_no_module_imports_a_module_that_imports_it_back():
    graph = import_graph()
    found = cycles(graph)
    assert found == [], describe(graph, found)


def test_the_apps_parts_import_each_other_in_one_direction_only():
    graph = coarsened(import_graph(), part)
    found = cycles(graph)
    assert found == [], describe(graph, found)


def test_the_app_never_imports_the_project():
    graph = import_graph()
    packages = coarsened(graph, lambda module: module.partition(".")[0])
    assert "segmentation" in packages["cutroom"]  # the project mounts the app
    back = {m: sorted(t for t in edges if t.startswith("cutroom"))
            for m, edges in graph.items() if m.startswith("segmentation")}
    assert cycles(packages) == [], {m: t for m, t in back.items() if t}


def test_the_graph_sees_imports_inside_functions_and_url_includes():
    graph = import_graph()
    assert "segmentation.models" in graph["cutroom.lanes"]  # inside capture_frames
    assert "segmentation.api.urls" in graph["cutroom.urls"]  # include("segmentation.api.urls")
    assert "segmentation.services.jobs" in graph["segmentation.services.captures"]


def test_it_finds_a_cycle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": {"e"}}
    assert cycles(graph) == [["a", "b", "c"]]


def test_no_service_imports_celery():
    importers = []
    for module, path in modules().items():
        if part(module) != "segmentation.services":
            continue
        names = imported_names(ast.parse(path.read_text()), module, path.name == "__init__.py")
        if any(name == "celery" or name.startswith("celery.") for name in names):
            importers.append(module)
    assert importers == []


# ---- motionlib ---------------------------------------------------------------------------
# The library is read the same way, every import counted: those under ``if TYPE_CHECKING:``
# too, since a circle of types is still two modules each of which needs the other to be
# read. The learner (``motionlib.adapt``) uses only the public names of the segmenters, so
# that the detector's stages can change without it noticing.

def motionlib_graph():
    known = package_modules(ROOT, "motionlib")
    graph = {}
    for module, path in known.items():
        if path.suffix != ".py":
            graph[module] = set()
            continue
        names = imported_names(ast.parse(path.read_text()), module, path.name == "__init__.py",
                               known)
        graph[module] = {name for name in names if name in known} - {module}
    return graph


def private_segmenter_names(module, source):
    tree = ast.parse(source)
    is_package = module == "motionlib.adapt"
    return private_uses(tree, list(imported_names(tree, module, is_package)),
                        "motionlib.segmenters")


def test_no_motionlib_module_imports_a_module_that_imports_it_back():
    graph = motionlib_graph()
    found = cycles(graph)
    assert found == [], describe(graph, found)


def test_the_motionlib_graph_counts_imports_only_type_checkers_see():
    source = "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from motionlib.take import Take\n"
    assert list(imported_names(ast.parse(source), "motionlib.x", False)) == [
        "typing.TYPE_CHECKING", "motionlib.take.Take"]
    assert "motionlib.segmenters.default._analysis" in motionlib_graph()[
        "motionlib.segmenters.default._peaks"]


def test_the_learner_uses_no_private_name_of_the_segmenters():
    found = {module: private_segmenter_names(module, path.read_text())
             for module, path in package_modules(ROOT, "motionlib").items()
             if module == "motionlib.adapt" or module.startswith("motionlib.adapt.")}
    assert {module: names for module, names in found.items() if names} == {}


def test_it_finds_a_private_segmenter_name_imported_or_reached():
    source = ("from motionlib.segmenters.default._peaks import cross_support\n"
              "from motionlib.segmenters.base import Segmentation, _checked\n"
              "from motionlib.segmenters import default\n"
              "def f(a):\n    return default._placement.place_stages(a), default.place(a)\n")
    assert private_segmenter_names("motionlib.adapt._x", source) == [
        "motionlib.segmenters.default._peaks.cross_support", "motionlib.segmenters.base._checked",
        "motionlib.segmenters.default._placement.place_stages",
        "motionlib.segmenters.default._placement"]
