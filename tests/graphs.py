"""Graph helpers the import-graph tests share."""

import ast


def cycles(graph):
    """The strongly connected components of more than one node (Tarjan), each sorted."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(node):
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for target in graph.get(node, ()):
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in on_stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return found


def package_modules(root, package):
    """{dotted name: path} of every module of ``package`` (a folder under ``root``): its
    sources, and its compiled extensions (``_parse.cpython-311-x86_64-linux-gnu.so`` is
    ``_parse``), which import nothing of the package."""
    found = {}
    for path in [*(root / package).rglob("*.py"), *(root / package).rglob("*.so")]:
        parts = list(path.relative_to(root).parts)
        parts[-1] = parts[-1].partition(".")[0]
        if parts[-1] == "__init__":
            parts.pop()
        found[".".join(parts)] = path
    return found


def private_uses(tree, imported, package):
    """The names of ``package``'s private parts a module uses: dotted names it imports
    (``imported``, as ``test_import_graph.imported_names`` gives them) or reaches as an
    attribute of a module of ``package`` it imported, with a part after ``package`` that
    starts with one underscore (``default._peaks``, ``base._checked``)."""
    def private(name):
        rest = name[len(package):].split(".")[1:] if name.startswith(package + ".") else []
        return any(p.startswith("_") and not p.startswith("__") for p in rest)

    found = [name for name in imported if private(name)]
    bound = {}  # local name -> the module of ``package`` it stands for
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            bound.update({a.asname or a.name.partition(".")[0]: a.name if a.asname else
                          a.name.partition(".")[0] for a in node.names})
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            bound.update({a.asname or a.name: f"{node.module}.{a.name}" for a in node.names})
    for node in ast.walk(tree):
        chain = []
        while isinstance(node, ast.Attribute):
            chain.insert(0, node.attr)
            node = node.value
        if chain and isinstance(node, ast.Name) and node.id in bound:
            name = ".".join([bound[node.id], *chain])
            if private(name) and name not in found:
                found.append(name)
    return found
