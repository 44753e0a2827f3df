"""The similar-clip search as an earlier commit shipped it, loaded from git, so that a
benchmark runs the old path beside the new one in the same process and run.

``load(rev)`` returns the modules ``similarity``, ``vector_index``, ``similar_index``,
``search`` and ``api_similar`` of ``rev``, each wired to the others of ``rev`` (and to this checkout
for everything else: models, serializers, descriptors), without touching the modules
the service imports.
"""

import subprocess
import sys
import types

from benchmarks.harness import REPO

# The last commit with the numpy inverted file, whole-file updates and the ORM re-ranking.
BEFORE = "45b52fc"


def _source(rev, path):
    return subprocess.run(["git", "show", f"{rev}:{path}"], cwd=REPO, check=True,
                          capture_output=True, text=True).stdout


def _module(name, source, **names):
    module = types.ModuleType(name)
    module.__file__ = f"<{name}>"
    exec(compile(source, module.__file__, "exec"), module.__dict__)  # noqa: S102
    for key, value in names.items():
        setattr(module, key, value)
    return module


def vector_index(rev=BEFORE):
    """Only ``rev``'s ``motionlib.vector_index`` (needs no Django)."""
    return _module("before_vector_index", _source(rev, "motionlib/vector_index.py"))


def load(rev=BEFORE):
    similarity = _module("before_similarity", _source(rev, "motionlib/similarity.py"))
    vector_index = _module("before_vector_index", _source(rev, "motionlib/vector_index.py"))
    # Its ``from motionlib.vector_index import IvfIndex`` must find the old module.
    saved = sys.modules["motionlib.vector_index"]
    sys.modules["motionlib.vector_index"] = vector_index
    try:
        similar_index = _module("before_similar_index",
                                _source(rev, "segmentation/similar_index.py"),
                                similarity=similarity)
    finally:
        sys.modules["motionlib.vector_index"] = saved
    search = _module("before_search", _source(rev, "segmentation/search.py"),
                     similar_index=similar_index, similarity=similarity)
    api = _module("before_api_similar", _source(rev, "segmentation/api/similar.py"), search=search)
    return types.SimpleNamespace(vector_index=vector_index, similar_index=similar_index,
                                 search=search, api_similar=api, similarity=similarity, rev=rev)
