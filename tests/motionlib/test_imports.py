"""motionlib is a plain numerical library: importing any of its modules imports neither
Django nor Blender's ``bpy`` (the FBX reader must import it only when it reads a file)."""

import subprocess
import sys

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
