"""The ctypes structures of planarvo._native against the C compiler's layout of
include/planarvo/planarvo.h: every structure's size and every field's offset, from a small C
program built with the system's C compiler (an independent reference: a field missed, misordered
or of the wrong type in the mirror moves an offset or the size). Skipped when the header or a C
compiler is not found."""
import ctypes
import os
import re
import shutil
import subprocess

import pytest

from planarvo import _native

HERE = os.path.dirname(os.path.abspath(__file__))
HEADER_DIR = os.path.normpath(os.path.join(HERE, "..", "..", "include"))


def c_name(cls_name):
    """Region -> planarvo_region, RollPitchOptions -> planarvo_roll_pitch_options, SE2 -> planarvo_se2."""
    return "planarvo_" + re.sub(r"(?<=[a-z0-9])(?=[A-Z])", "_", cls_name).lower()


def structures():
    out = []
    for name in dir(_native):
        obj = getattr(_native, name)
        if isinstance(obj, type) and issubclass(obj, ctypes.Structure) and obj is not ctypes.Structure:
            out.append(obj)
    return sorted(out, key=lambda c: c.__name__)


def test_every_structure_matches_the_c_layout(tmp_path):
    cc = shutil.which("cc") or shutil.which("gcc")
    if not cc or not os.path.isfile(os.path.join(HEADER_DIR, "planarvo", "planarvo.h")):
        pytest.skip("no C compiler or no header beside the package")
    structs = structures()
    assert len(structs) >= 20, "the mirror should hold every struct of the header"
    lines = ["#include <stddef.h>", "#include <stdio.h>", "#include <planarvo/planarvo.h>", "int main(void) {"]
    for cls in structs:
        cn = c_name(cls.__name__)
        lines.append(f'  printf("{cls.__name__} size %zu\\n", sizeof({cn}));')
        for field in cls._fields_:
            lines.append(f'  printf("{cls.__name__} {field[0]} %zu\\n", offsetof({cn}, {field[0]}));')
    lines += ["  return 0;", "}"]
    src = tmp_path / "layout.c"
    src.write_text("\n".join(lines) + "\n")
    exe = tmp_path / "layout"
    build = subprocess.run([cc, "-I", HEADER_DIR, str(src), "-o", str(exe)], capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    c_layout = {}
    for line in subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout.splitlines():
        cls_name, field, value = line.split()
        c_layout[(cls_name, field)] = int(value)
    mismatches = []
    for cls in structs:
        if ctypes.sizeof(cls) != c_layout[(cls.__name__, "size")]:
            mismatches.append(f"{cls.__name__}: size {ctypes.sizeof(cls)} != C {c_layout[(cls.__name__, 'size')]}")
        for field in cls._fields_:
            offset = getattr(cls, field[0]).offset
            if offset != c_layout[(cls.__name__, field[0])]:
                mismatches.append(f"{cls.__name__}.{field[0]}: offset {offset} != C {c_layout[(cls.__name__, field[0])]}")
    assert not mismatches, "\n".join(mismatches)


def test_every_function_of_the_header_has_a_prototype_from_the_library():
    """The prototypes come from the library's signature table, which the build generates from the
    headers: every PLANARVO_API function the header declares (read here from the header's text, an
    independent list) is declared with ctypes, with as many argument types as it has parameters."""
    header = open(os.path.join(HEADER_DIR, "planarvo", "planarvo.h")).read()
    for extra in ("dataset.h", "calibration.h", "mosaic.h"):
        header += open(os.path.join(HEADER_DIR, "planarvo", extra)).read()
    header = re.sub(r"/\*.*?\*/", " ", header, flags=re.S)
    declared = dict(re.findall(r"PLANARVO_API\s+[^;{]*?\b(planarvo_\w+)\s*\(([^;{]*?)\)\s*;", header, flags=re.S))
    table = _native._signatures(_native.lib.planarvo_api_signatures().decode())
    assert set(table) == set(declared)
    for name, params in declared.items():
        n = 0 if params.strip() in ("", "void") else params.count(",") + 1
        assert len(table[name][1]) == n, name
        assert getattr(_native.lib, name).argtypes == table[name][1], name
