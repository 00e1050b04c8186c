# souptet.read_parts and mesh(..., parts=...): each tet's part (issue 38).
import os

import numpy as np
import pytest

import souptet
from conftest import box


def nested(tmp_path):
    """flesh [0,4]x[0,2]^2 with bone [0.5,3.5]x[0.7,1.3]^2 inside, as an OBJ."""
    V1, F1 = box((0, 0, 0), (4, 2, 2))
    V2, F2 = box((0.5, 0.7, 0.7), (3.5, 1.3, 1.3))
    p = os.path.join(str(tmp_path), "nested.obj")
    with open(p, "w") as f:
        f.write("o flesh\n")
        f.writelines("v %r %r %r\n" % tuple(v) for v in V1)
        f.writelines("f %d %d %d\n" % tuple(t + 1) for t in F1)
        f.write("o bone\n")
        f.writelines("v %r %r %r\n" % tuple(v) for v in V2)
        f.writelines("f %d %d %d\n" % tuple(t + 9) for t in F2)
    return p


def test_read_parts_names(tmp_path):
    V, F, P, N = souptet.read_parts(nested(tmp_path))
    assert N == ["flesh", "bone"]
    assert P.dtype == np.int32 and list(P) == [0] * 12 + [1] * 12
    assert len(V) == 16 and len(F) == 24


def test_mesh_parts_tag_the_inner_part(tmp_path):
    V, F, P, N = souptet.read_parts(nested(tmp_path))
    r = souptet.mesh(V, F, cells=8, tries=1, parts=P, part_names=N)
    assert r.part_names == ["flesh", "bone"]
    assert r.parts.dtype == np.int32 and r.parts.shape == (len(r.tets),)
    assert np.all((r.part_share >= 0) & (r.part_share <= 1))
    c = r.points[r.tets].mean(axis=1)
    inb = np.all((c > [0.5, 0.7, 0.7]) & (c < [3.5, 1.3, 1.3]), axis=1)
    assert inb.sum() > 0 and np.mean(r.parts[inb] == 1) >= 0.9
    assert np.mean(r.parts[~inb] == 0) >= 0.9
    out = os.path.join(str(tmp_path), "n.msh")
    r.write(out)
    text = open(out).read()
    assert '3 3 "flesh"' in text and '3 4 "bone"' in text


def test_mesh_without_parts_has_none():
    V, F = box()
    r = souptet.mesh(V, F, cells=4, tries=1)
    assert r.parts is None and r.part_share is None and r.part_names is None


def test_mesh_pieces_and_names_default():
    V1, F1 = box()
    V2, F2 = box((2, 0, 0), (3, 1, 1))
    V = np.vstack([V1, V2])
    F = np.vstack([F1, F2 + 8])
    r = souptet.mesh(V, F, cells=6, tries=1, parts="pieces")
    assert r.part_names == ["piece_0", "piece_1"]
    assert set(np.unique(r.parts)) == {0, 1}
    r = souptet.mesh(V, F, cells=6, tries=1, parts=np.repeat([1, 0], 12))
    assert r.part_names == ["part_0", "part_1"]
    assert np.mean(r.parts[r.points[r.tets].mean(axis=1)[:, 0] < 1] == 1) >= 0.9


def test_parts_bad_input():
    V, F = box()
    with pytest.raises(souptet.Error, match="one entry per row of F"):
        souptet.mesh(V, F, parts=[0, 1])
    with pytest.raises(souptet.Error, match="not a part index"):
        souptet.mesh(V, F, parts=np.full(12, 70000))
    with pytest.raises(souptet.Error, match="parts must be"):
        souptet.mesh(V, F, parts="bogus")
    with pytest.raises(TypeError):
        souptet.mesh(V, F, parts=np.zeros(12, int), part_names=[1])
