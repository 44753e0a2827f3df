"""motionlib is a plain numerical library: importing it must not import Django."""

import subprocess
import sys


def test_it_imports_motionlib_without_django():
    code = ("import sys, motionlib, motionlib.cli, motionlib.synth, motionlib.adapt, "
            "motionlib.tuning; "
            "print('django' in sys.modules, any(m.startswith('django') for m in sys.modules))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True)
    assert result.stdout.split() == ["False", "False"]
