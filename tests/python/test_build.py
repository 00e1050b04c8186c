# What the extensions link: _core the C core alone (an artist's machine
# needs neither VTK nor OpenVDB), _io the io library; RUNPATH into build/.
import glob
import os
import shutil
import subprocess

import pytest

import souptet
from conftest import PYDIR


def dynamic(path):
    out = subprocess.run(["readelf", "-d", path], capture_output=True, text=True,
                         check=True).stdout
    needed = [l.split("[")[1].rstrip("]") for l in out.splitlines() if "(NEEDED)" in l]
    runpath = [l.split("[")[1].rstrip("]") for l in out.splitlines() if "(RUNPATH)" in l]
    return needed, runpath


def ext(name):
    return glob.glob(os.path.join(PYDIR, "souptet", name + ".*so"))[0]


@pytest.mark.skipif(not shutil.which("readelf"), reason="no readelf (binutils)")
def test_core_needs_only_the_core_library():
    needed, runpath = dynamic(ext("_core"))
    assert "libsouptet.so.0" in needed
    assert not any("vtk" in n or "openvdb" in n or "souptet-io" in n for n in needed), needed
    assert runpath == ["$ORIGIN/../.."]
    lib = os.path.join(PYDIR, "..", "libsouptet.so.0")
    libneeded, _ = dynamic(lib)
    assert not any("vtk" in n or "openvdb" in n or "tbb" in n for n in libneeded), libneeded


@pytest.mark.skipif(not shutil.which("readelf"), reason="no readelf (binutils)")
def test_io_needs_the_io_library():
    needed, runpath = dynamic(ext("_io"))
    assert "libsouptet-io.so.0" in needed and "libsouptet.so.0" in needed
    assert runpath == ["$ORIGIN/../.."]


def test_module_comes_from_the_build():
    assert os.path.realpath(souptet.__file__).startswith(os.path.realpath(PYDIR))
