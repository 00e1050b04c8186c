# The Python defaults are the CLI's (soupmesh --help, soupdist --help and
# the library's st_pipeline_params_default), except where documented.
import inspect
import os
import re
import subprocess
import sys

import numpy as np

import pytest

import souptet
from conftest import PYDIR, tool

# Deliberate differences, each said in the docstring.
DIFFERENT = {"tries": (4, 1)}   # python, soupmesh


def help_default(toolname, opt):
    """The 'default X' of an option's block in TOOL --help (as defaults_check.py)."""
    h = subprocess.run([tool(toolname), "--help"], capture_output=True, text=True).stdout
    lines = h.splitlines()
    head = re.compile(r"^\s{2,}(?:-\w,\s+)?(-\w|--[\w-]+)\b")
    for i, line in enumerate(lines):
        if re.match(r"^\s{2,}(?:-\w,\s+)?" + re.escape(opt) + r"\b", line):
            block = [line]
            for l2 in lines[i + 1:]:
                if head.match(l2) or not l2.startswith("        "):
                    break
                block.append(l2)
            m = re.search(r"default:?\s+([^\s;,)]+)", " ".join(block), re.I)
            assert m, (toolname, opt, block)
            v = m.group(1).rstrip(".,;:)")
            return float(v)
    raise AssertionError("%s --help has no %s" % (toolname, opt))


def py_default(fn, name):
    return inspect.signature(fn).parameters[name].default


SHARED = [  # python function, parameter, tool, option
    (souptet.mesh, "cells", "soupmesh", "--cells"),
    (souptet.mesh, "tries", "soupmesh", "--tries"),
    (souptet.mesh, "seed", "soupmesh", "--seed"),
    (souptet.mesh, "offset", "soupmesh", "--offset"),
    (souptet.pseudo_volume, "resolution", "soupdist", "--voxels"),
    (souptet.distance, "resolution", "soupdist", "--voxels"),
    (souptet.distance, "band", "soupdist", "--band"),
]


@pytest.mark.parametrize("fn,name,toolname,opt", SHARED,
                         ids=["%s-%s" % (s[0].__name__, s[1]) for s in SHARED])
def test_default_matches_cli(fn, name, toolname, opt):
    got, want = py_default(fn, name), help_default(toolname, opt)
    if name in DIFFERENT and fn is souptet.mesh:
        assert (got, want) == DIFFERENT[name]
        assert "soupmesh's default is %d" % want in fn.__doc__
    else:
        assert got == want


def test_library_defaults():
    lib = souptet._core.library_defaults()
    for name in ("cells", "seed", "offset"):
        assert py_default(souptet.mesh, name) == lib[name]
    assert lib["tries"] == DIFFERENT["tries"][1]
    assert py_default(souptet.pseudo_volume, "resolution") == lib["resolution"]
    # size, tets None: from cells, no target; threads 0: all cores
    assert py_default(souptet.mesh, "size") is None and py_default(souptet.mesh, "tets") is None
    assert py_default(souptet.mesh, "threads") == 0


def test_docstrings_name_every_parameter():
    for fn in (souptet.read, souptet.mesh, souptet.pseudo_volume, souptet.distance,
               souptet.wrap, souptet.MeshResult.write):
        for p in inspect.signature(fn).parameters:
            if p != "self":
                assert re.search(r"^\s+(\w+, )?%s\b" % p, fn.__doc__, re.M), (fn.__name__, p)


def test_stub_lists_the_api():
    stub = open(os.path.join(PYDIR, "souptet", "__init__.pyi")).read()
    for name in souptet.__all__:
        assert re.search(r"^(def|class) %s\b" % name, stub, re.M), name
    assert os.path.exists(os.path.join(PYDIR, "souptet", "py.typed"))


def test_without_io_module(tmp_path):
    # _io (OpenVDB, VTK) missing: wrap and .vtu say so, the rest works
    code = """
import sys
sys.path.insert(0, %r)
sys.modules['souptet._io'] = None
import souptet, numpy as np
from conftest import box
V, F = box()
m = souptet.mesh(V, F, cells=3, tries=1)
m.write(%r)
for f in (lambda: souptet.wrap(V, F), lambda: m.write(%r)):
    try:
        f()
        sys.exit('no error')
    except souptet.Error as e:
        assert 'OpenVDB' in str(e) and 'libsouptet-io' in str(e), str(e)
print('ok')
""" % (PYDIR, str(tmp_path / "a.msh"), str(tmp_path / "a.vtu"))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       cwd=os.path.dirname(__file__))
    assert r.stdout.strip() == "ok", r.stderr
    assert os.path.exists(str(tmp_path / "a.msh")) and not os.path.exists(str(tmp_path / "a.vtu"))


def test_float32_parameter():
    from conftest import box
    V, F = box()
    m = souptet.mesh(V, F, cells=3, tries=1, float32=False)
    assert m.encloses
    # float32=True: every point is a float32 value, and the mesh still
    # encloses (checked exactly by the library on the rounded points, and
    # here the same as soupmesh --float32 gives)
    V2 = V * (1.0 + 1e-9) + 20.3   # off the float grid
    m32 = souptet.mesh(V2, F, cells=4, tries=1, float32=True)
    assert m32.encloses
    assert np.array_equal(m32.points.astype(np.float32).astype(np.float64), m32.points)


def test_fill_defaults_match_cli():
    # fill_holes and symmetry: the library's pseudo-volume defaults, as
    # soupsign --help says them ("default on" / "default off")
    h = subprocess.run([tool("soupsign"), "--help"], capture_output=True, text=True).stdout
    said = {}
    for opt in ("--fill-holes", "--symmetry"):
        block = h[h.index(opt):]
        m = re.search(r"default:?\s+(on|off)", block)
        assert m, opt
        said[opt] = m.group(1) == "on"
    for fn in (souptet.mesh, souptet.pseudo_volume, souptet.wrap):
        assert py_default(fn, "fill_holes") is said["--fill-holes"]
        assert py_default(fn, "symmetry") is said["--symmetry"]
