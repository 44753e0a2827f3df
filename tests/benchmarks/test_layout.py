"""The benchmarks are one package: imported as ``benchmarks.*`` (never through an edited
``sys.path``), with no import circle among its modules and no copy of old product code."""

import ast

from benchmarks.harness import PACKAGE


def modules():
    """{dotted name: path} of every module of the package."""
    found = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def imports(path, known):
    """The package's modules that ``path`` imports (at any depth of its code)."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name in known}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out |= {f"{node.module}.{a.name}" for a in node.names
                    if f"{node.module}.{a.name}" in known}
            out |= {node.module} & known.keys()
    return out


def test_no_module_edits_the_import_path():
    for name, path in modules().items():
        assert "sys.path" not in path.read_text(), name


def test_no_import_circle_among_the_benchmarks():
    known = modules()
    graph = {name: imports(path, known) - {name} for name, path in known.items()}
    # A package imports its submodules only through them; its __init__ is no edge back.
    graph = {name: {m for m in deps if not name.startswith(m + ".")}
             for name, deps in graph.items()}
    done, stack = set(), []

    def visit(name):
        assert name not in stack, "import circle: " + " -> ".join([*stack, name])
        if name in done:
            return
        stack.append(name)
        for dep in sorted(graph[name]):
            visit(dep)
        stack.pop()
        done.add(name)

    for name in sorted(graph):
        visit(name)


def test_every_benchmark_lives_in_a_subpackage_of_its_subject():
    loose = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert loose == ["__init__.py", "__main__.py", "registry.py"]
