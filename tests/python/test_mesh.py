# souptet.mesh: the same mesh as soupmesh, its result's parts, progress,
# write() round trips.
import os
import subprocess

import numpy as np
import pytest

import souptet
from conftest import BUNNY, box, tool


def read_tetgen(base):
    """Points and 0-based tets of a TetGen pair written at full precision."""
    def rows(path):
        return [l.split() for l in open(path) if l.strip() and not l.startswith("#")]
    n = rows(base + ".node")
    e = rows(base + ".ele")
    P = np.array([[float(x) for x in r[1:4]] for r in n[1:int(n[0][0]) + 1]])
    T = np.array([[int(x) for x in r[1:5]] for r in e[1:int(e[0][0]) + 1]]) - 1
    return P, T


def test_same_mesh_as_soupmesh(tmp_path, bunny, bunny_mesh):
    base = str(tmp_path / "cli")
    subprocess.run([tool("soupmesh"), "-q", "--cells", "6", "--tries", "1", "-o",
                    base + ".node", BUNNY], check=True)
    P, T = read_tetgen(base)
    m = bunny_mesh
    # .node holds 17 significant digits: the doubles, bit for bit
    assert P.shape == m.points.shape
    assert np.array_equal(P.view(np.uint64), m.points.view(np.uint64))
    assert np.array_equal(T, m.tets)


def test_same_mesh_with_seed_offset_tries(tmp_path, bunny):
    base = str(tmp_path / "cli")
    subprocess.run([tool("soupmesh"), "-q", "--cells", "5", "--tries", "2", "--seed", "7",
                    "--offset", "0.5", "-o", base + ".node", BUNNY], check=True)
    P, T = read_tetgen(base)
    m = souptet.mesh(*bunny, cells=5, tries=2, seed=7, offset=0.5)
    assert np.array_equal(P.view(np.uint64), m.points.view(np.uint64))
    assert np.array_equal(T, m.tets)


def test_result_parts(bunny, bunny_mesh):
    V, F = bunny
    m = bunny_mesh
    assert m.points.dtype == np.float64 and m.points.shape[1] == 3
    assert m.tets.dtype == np.int64 and m.tets.shape[1] == 4
    assert m.tets.min() >= 0 and m.tets.max() < len(m.points)
    assert m.encloses is True and m.converged is True
    assert 0 < m.min_dihedral < m.max_dihedral < 180
    assert m.h > 0 and m.seed == 1 and m.candidates == 1
    # positively oriented tets
    a, b, c, d = (m.points[m.tets[:, i]] for i in range(4))
    vol = np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) / 6
    assert (vol > 0).all()
    # the boundary: closed (every edge twice, once each way) and outward
    B = m.boundary
    assert B.dtype == np.int64 and B.shape[1] == 3
    edges = np.concatenate([B[:, [0, 1]], B[:, [1, 2]], B[:, [2, 0]]])
    fwd = set(map(tuple, edges))
    assert len(fwd) == len(edges) and all((j, i) in fwd for i, j in fwd)
    p0, p1, p2 = (m.points[B[:, i]] for i in range(3))
    enclosed = np.einsum("ij,ij->i", p0, np.cross(p1, p2)).sum() / 6
    assert enclosed == pytest.approx(vol.sum(), rel=1e-9)
    # the embedding: every input vertex in a tet, at its barycentric point
    assert m.embed_tet.shape == (len(V),) and m.embed_bary.shape == (len(V), 4)
    assert (m.embed_tet >= 0).all() and (m.embed_bary >= 0).all()
    X = np.einsum("ij,ijk->ik", m.embed_bary, m.points[m.tets[m.embed_tet]])
    assert np.abs(X - V).max() < 1e-9 * np.abs(V).max()
    assert "encloses" in repr(m)


def test_embed_matches_soupmesh(tmp_path, bunny_mesh):
    p = str(tmp_path / "e.txt")
    subprocess.run([tool("soupmesh"), "-q", "--cells", "6", "--tries", "1", "-o",
                    str(tmp_path / "m.msh"), "--embed", p, BUNNY], check=True)
    rows = np.array([[float(x) for x in l.split()] for l in open(p) if not l.startswith("#")])
    assert np.array_equal(rows[:, 0].astype(np.int64), bunny_mesh.embed_tet)
    assert np.array_equal(rows[:, 1:], bunny_mesh.embed_bary)


def test_threads_do_not_change_the_mesh(bunny, bunny_mesh):
    m = souptet.mesh(*bunny, cells=6, tries=1, threads=1)
    assert np.array_equal(m.points, bunny_mesh.points)
    assert np.array_equal(m.tets, bunny_mesh.tets)


def test_size_and_tets(bunny, bunny_mesh):
    m = souptet.mesh(*bunny, size=bunny_mesh.h, tries=1)
    assert m.h == bunny_mesh.h
    m2 = souptet.mesh(*bunny, cells=5, tets=1500, tries=1)
    assert 1200 <= len(m2.tets) <= 1800


def test_box_and_lists():
    V, F = box()
    m = souptet.mesh(V.tolist(), F.tolist(), cells=4, tries=1)
    assert m.encloses
    # int32 indices and float32 coordinates are taken too
    m2 = souptet.mesh(V.astype(np.float32), F.astype(np.int32), cells=4, tries=1)
    assert np.array_equal(m.points, m2.points)


def test_progress_events(bunny):
    events = []
    souptet.mesh(*bunny, cells=5, tries=2, progress=events.append)
    whats = [e["what"] for e in events]
    for w in ("field", "sculpted", "iteration", "candidate", "progress"):
        assert w in whats, w
    field = events[whats.index("field")]
    assert len(field["field_dims"]) == 3 and field["voxel"] > 0
    sculpted = [e for e in events if e["what"] == "sculpted"]
    assert sorted(e["k"] for e in sculpted) == [0, 1]
    assert all(e["tets"] > 0 and e["h"] > 0 for e in sculpted)
    assert all(0.0 <= e["fraction"] <= 1.0 for e in events)
    it = next(e for e in events if e["what"] == "iteration")
    assert it["phase"] in ("fit", "quality") and it["iteration"] >= 1


class Stop(Exception):
    pass


def test_progress_exception_propagates(bunny, bunny_mesh):
    seen = []

    def cb(ev):
        seen.append(ev["what"])
        if ev["what"] == "sculpted":
            raise Stop("enough")
    with pytest.raises(Stop):
        souptet.mesh(*bunny, cells=6, tries=1, progress=cb)
    assert "sculpted" in seen
    # and the next call works
    m = souptet.mesh(*bunny, cells=6, tries=1)
    assert np.array_equal(m.tets, bunny_mesh.tets)


def test_to_meshio(bunny_mesh):
    mm = bunny_mesh.to_meshio()
    assert np.array_equal(mm.points, bunny_mesh.points)
    assert np.array_equal(mm.cells_dict["tetra"], bunny_mesh.tets)


@pytest.mark.parametrize("name,kw", [("m41.msh", {}), ("m22.msh", {"msh_version": 22}),
                                     ("mb.msh", {"binary": True}), ("m.mesh", {}),
                                     ("m.node", {}), ("m.vtu", {})])
def test_write_roundtrip_meshio(tmp_path, bunny_mesh, name, kw):
    import meshio
    p = str(tmp_path / name)
    bunny_mesh.write(p, **kw)
    mm = meshio.read(p if not p.endswith(".node") else p, file_format="tetgen" if p.endswith(".node") else None)
    assert np.array_equal(mm.points, bunny_mesh.points)
    tets = mm.cells_dict["tetra"]
    if p.endswith(".node"):   # meshio keeps TetGen's 1-based numbers as read
        tets = tets - tets.min() if tets.min() == 1 else tets
    assert np.array_equal(tets, bunny_mesh.tets)
    if name.endswith(".msh") or name.endswith(".mesh"):
        tri = mm.cells_dict["triangle"]
        assert len(tri) == len(bunny_mesh.boundary)


def test_write_same_bytes_as_soupmesh(tmp_path, bunny_mesh):
    subprocess.run([tool("soupmesh"), "-q", "--cells", "6", "--tries", "1", "-o",
                    str(tmp_path / "cli.msh"), BUNNY], check=True)
    bunny_mesh.write(str(tmp_path / "py.msh"))

    def body(p):   # without the comments (history, source)
        t = open(p).read()
        a, b = t.index("$Comments"), t.index("$EndComments")
        return t[:a] + t[b:]
    assert body(str(tmp_path / "cli.msh")) == body(str(tmp_path / "py.msh"))


def test_write_errors(tmp_path, bunny_mesh):
    with pytest.raises(souptet.Error):
        bunny_mesh.write(str(tmp_path / "m.xyz"))
    with pytest.raises(OSError):
        bunny_mesh.write(str(tmp_path / "no" / "such" / "dir" / "m.msh"))
    with pytest.raises(souptet.Error):
        bunny_mesh.write(str(tmp_path / "m.msh"), msh_version=3)
    assert not os.listdir(str(tmp_path))
