"""The Python examples of README.md and python/README.md run as written, in a directory where
"drive" is a simulated data set (what the examples name), and print what they promise."""
import os
import re
import subprocess
import sys

import pytest

SOURCE = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def python_blocks(path):
    with open(path) as f:
        return re.findall(r"```python\n(.*?)```", f.read(), re.S)


@pytest.mark.parametrize("readme", ["README.md", os.path.join("python", "README.md")])
def test_readme_python_examples_run_as_written(readme, drive, tmp_path):
    blocks = python_blocks(os.path.join(SOURCE, readme))
    assert blocks, "no python example in " + readme
    os.symlink(drive, tmp_path / "drive")
    for k, code in enumerate(blocks):
        script = tmp_path / ("example%d.py" % k)
        script.write_text(code)
        r = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True,
                           env=dict(os.environ), timeout=300)
        assert r.returncode == 0, "%s example %d:\n%s\n%s" % (readme, k, code, r.stderr)
        if "tracker.track" in code:  # the tracking loop prints one line per frame, tracked
            lines = r.stdout.splitlines()
            assert len(lines) > 3 and all(l.startswith("TrackStatus.") for l in lines), r.stdout[:500]
            assert sum(l.startswith("TrackStatus.OK") for l in lines) >= len(lines) - 2
