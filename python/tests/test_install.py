"""The package as users get it: the example program, and `cmake --install` into a fresh prefix
imported with only PYTHONPATH set (the library found beside the package)."""
import os
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.normpath(os.path.join(HERE, "..", ".."))


def test_example_calibrates_simulated_drive(tmp_path):
    env = dict(os.environ, PYTHONPATH=os.path.join(SOURCE, "python"))
    out = subprocess.run([sys.executable, os.path.join(SOURCE, "examples", "python", "calibrate_simulated_drive.py"),
                          "--seconds", "5", "--plot", str(tmp_path / "trajectory.png")],
                         env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    for name in ("x", "y", "z", "roll", "pitch", "yaw"):
        assert "\n%-6s " % name in out.stdout
    assert "calibrated" in out.stdout and "sigma" in out.stdout


def test_installed_package_finds_its_library(tmp_path):
    build = os.environ.get("PLANARVO_BUILD_DIR")
    if not build:
        pytest.skip("PLANARVO_BUILD_DIR not set (CTest sets it)")
    prefix = tmp_path / "prefix"
    subprocess.run([os.environ.get("CMAKE", "cmake"), "--install", build, "--prefix", str(prefix)], check=True,
                   capture_output=True)
    site = prefix / "lib" / "python3" / "dist-packages"
    assert (site / "planarvo" / "py.typed").exists()
    env = {k: v for k, v in os.environ.items() if k not in ("PLANARVO_LIBRARY", "PYTHONPATH", "LD_LIBRARY_PATH")}
    env["PYTHONPATH"] = str(site)
    code = "import planarvo, planarvo._native as n; print(planarvo.__file__); print(n.lib._name); " \
           "print(planarvo.default_texture())"
    out = subprocess.run([sys.executable, "-c", code],
                         cwd=str(tmp_path), env=env, capture_output=True, text=True, check=True)
    package, library, texture = out.stdout.split("\n")[:3]
    assert package.startswith(str(site)) and library.startswith(str(prefix)), out.stdout
    assert texture.startswith(str(prefix)), out.stdout
