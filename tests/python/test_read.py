# souptet.read: every input format the tools read, and its errors.
import errno
import os

import numpy as np
import pytest

import souptet
from conftest import BUNNY, box


def write_formats(d, V, F):
    """The box as OBJ, OFF, ASCII PLY and ASCII STL files in d."""
    paths = {}
    p = os.path.join(d, "b.obj")
    with open(p, "w") as f:
        f.writelines("v %r %r %r\n" % tuple(v) for v in V)
        f.writelines("f %d %d %d\n" % tuple(t + 1) for t in F)
    paths["obj"] = p
    p = os.path.join(d, "b.off")
    with open(p, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(V), len(F)))
        f.writelines("%r %r %r\n" % tuple(v) for v in V)
        f.writelines("3 %d %d %d\n" % tuple(t) for t in F)
    paths["off"] = p
    p = os.path.join(d, "b.ply")
    with open(p, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\nproperty double y\n"
                "property double z\nelement face %d\nproperty list uchar int vertex_indices\n"
                "end_header\n" % (len(V), len(F)))
        f.writelines("%r %r %r\n" % tuple(v) for v in V)
        f.writelines("3 %d %d %d\n" % tuple(t) for t in F)
    paths["ply"] = p
    p = os.path.join(d, "b.stl")
    with open(p, "w") as f:
        f.write("solid b\n")
        for t in F:
            f.write("facet normal 0 0 0\nouter loop\n")
            f.writelines("vertex %r %r %r\n" % tuple(V[i]) for i in t)
            f.write("endloop\nendfacet\n")
        f.write("endsolid b\n")
    paths["stl"] = p
    return paths


def test_read_bunny_types():
    V, F = souptet.read(BUNNY)
    assert V.dtype == np.float64 and V.shape == (1839, 3)
    assert F.dtype == np.int64 and F.shape == (3674, 3)
    assert F.min() >= 0 and F.max() < len(V)


@pytest.mark.parametrize("fmt", ["obj", "off", "ply", "stl"])
def test_read_formats(tmp_path, fmt):
    V, F = box((0.5, -1.0, 2.0), (1.75, 3.0, 2.5))
    p = write_formats(str(tmp_path), V, F)[fmt]
    V2, F2 = souptet.read(p)
    assert len(F2) == 12
    # the same triangles, as points (STL repeats vertices: compare corners)
    assert np.array_equal(V2[F2], V[F])


def test_read_pathlike_and_bytes(tmp_path):
    V, F = box()
    p = write_formats(str(tmp_path), V, F)["obj"]
    a = souptet.read(tmp_path / "b.obj")
    b = souptet.read(p.encode())
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_read_missing_is_oserror(tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        souptet.read(str(tmp_path / "nope.obj"))
    assert e.value.errno == errno.ENOENT
    assert e.value.filename == str(tmp_path / "nope.obj")


def test_read_directory_is_oserror(tmp_path):
    with pytest.raises(OSError):
        souptet.read(str(tmp_path))


def test_read_bad_data_is_error(tmp_path):
    p = tmp_path / "bad.obj"
    p.write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    with pytest.raises(souptet.Error) as e:
        souptet.read(str(p))
    assert isinstance(e.value, ValueError)
    assert "bad.obj" in str(e.value) and e.value.line == 3
    assert e.value.status == "bad input"
    # and the module still works
    assert souptet.read(BUNNY)[1].shape == (3674, 3)


def test_read_unknown_extension(tmp_path):
    p = tmp_path / "x.txt"
    p.write_text("hello\n")
    with pytest.raises(souptet.Error):
        souptet.read(str(p))
