"""The package's annotations (issue 25, item 5: type hints on every public call, a py.typed
marker, mypy --strict clean on the examples). mypy checks examples/python/*.py and, through their
imports, every module of the planarvo package (not planarvo.plot, which matplotlib's missing stubs
leave untyped). Skipped when the interpreter running the tests has no mypy (Debian:
python3-mypy, scripts/install-deps.sh); mypy runs under that same interpreter, whose numpy
supplies numpy's own stubs."""
import glob
import os
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.normpath(os.path.join(HERE, "..", ".."))


def test_package_has_a_py_typed_marker():
    assert os.path.isfile(os.path.join(SOURCE, "python", "planarvo", "py.typed"))


def test_examples_and_package_pass_mypy_strict(tmp_path):
    if subprocess.run([sys.executable, "-m", "mypy", "--version"], capture_output=True).returncode != 0:
        pytest.skip("mypy is not installed for %s (Debian: apt-get install python3-mypy)" % sys.executable)
    examples = sorted(glob.glob(os.path.join(SOURCE, "examples", "python", "*.py")))
    assert examples
    env = dict(os.environ, MYPYPATH=os.path.join(SOURCE, "python"))
    # --config-file= : no configuration of the user's (~/.config/mypy/config) changes the rules.
    command = [sys.executable, "-m", "mypy", "--strict", "--config-file=", "--cache-dir", str(tmp_path / "cache"),
               *examples]
    out = subprocess.run(command, cwd=SOURCE, env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, "mypy --strict failed:\n" + out.stdout + out.stderr
