# pseudo_volume, distance and wrap against soupdist, soupsign, soupwrap.
import math
import subprocess

import numpy as np
import pytest

import souptet
from conftest import BUNNY, box, tool


def read_vti(path):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLImageDataReader
    r = vtkXMLImageDataReader()
    r.SetFileName(path)
    r.Update()
    im = r.GetOutput()
    a = vtk_to_numpy(im.GetPointData().GetArray(0))
    d = im.GetDimensions()
    return a.reshape(d[::-1]).transpose(), im.GetOrigin(), im.GetSpacing()[0]


def test_pseudo_volume_same_as_soupsign(tmp_path, bunny):
    p = str(tmp_path / "s.vti")
    dist = subprocess.Popen([tool("soupdist"), "-q", "-r", "40", BUNNY], stdout=subprocess.PIPE)
    subprocess.run([tool("soupsign"), "-q", "-o", p], stdin=dist.stdout, check=True)
    assert dist.wait() == 0
    a, origin, voxel = read_vti(p)
    pv = souptet.pseudo_volume(*bunny, resolution=40)
    assert pv.inside.dtype == np.bool_ and pv.inside.shape == a.shape
    assert np.array_equal(pv.inside, a < 0)
    assert np.array_equal(pv.values, a)
    assert pv.origin == tuple(origin) and pv.voxel == voxel
    assert pv.inside.sum() > 1000
    assert "40" in repr(pv) or "x" in repr(pv)


def test_pseudo_volume_index_order():
    # a box off-center in a long domain: inside voxels where the box is
    V, F = box((0.0, 0.0, 0.0), (4.0, 1.0, 2.0))
    pv = souptet.pseudo_volume(V, F, resolution=16)
    nx, ny, nz = pv.inside.shape
    assert nx > nz > ny   # [i, j, k] with x the longest
    i, j, k = np.nonzero(pv.inside)
    centers = np.array(pv.origin) + pv.voxel * np.stack([i, j, k], 1)
    assert (centers >= -1e-12).all() and (centers <= [4, 1, 2]).all()


def test_distance_same_as_soupdist(tmp_path, bunny):
    p = str(tmp_path / "d.vti")
    subprocess.run([tool("soupdist"), "-q", "-r", "24", "-o", p, BUNNY], check=True)
    a, origin, voxel = read_vti(p)
    d = souptet.distance(*bunny, resolution=24)
    assert d.values.dtype == np.float32
    assert np.array_equal(d.values, a)
    assert d.origin == tuple(origin) and d.voxel == voxel
    assert d.band == pytest.approx(3 * voxel)
    full = souptet.distance(*bunny, resolution=24, band=math.inf)
    assert full.band == math.inf and full.values.max() > d.values.max()
    near = d.values < d.band
    assert np.array_equal(full.values[near], d.values[near])


def test_wrap_same_as_soupwrap(tmp_path, bunny):
    p = str(tmp_path / "w.obj")
    subprocess.run([tool("soupwrap"), "-q", "--surface", BUNNY, "-r", "24", "-o", p], check=True)
    Vc, Fc = souptet.read(p)
    V2, F2 = souptet.wrap(*bunny, resolution=24)
    assert V2.dtype == np.float64 and F2.dtype == np.int64
    assert np.array_equal(F2, Fc)
    assert np.array_equal(V2.astype(np.float32), Vc.astype(np.float32))
    # closed: every edge on two triangles, once each way
    e = np.concatenate([F2[:, [0, 1]], F2[:, [1, 2]], F2[:, [2, 0]]])
    s = set(map(tuple, e))
    assert len(s) == len(e) and all((j, i) in s for i, j in s)


def holed_cylinder(deg):
    """A closed 64-sided cylinder (radius 1, z in [-1, 1]) without the side's
    segments whose middle angle is below deg degrees (as soupsign.t's)."""
    n = 64
    a = 2 * np.pi * np.arange(n) / n
    V = np.zeros((2 * n + 2, 3))
    V[0:2 * n:2] = np.stack([np.cos(a), np.sin(a), -np.ones(n)], 1)
    V[1:2 * n:2] = np.stack([np.cos(a), np.sin(a), np.ones(n)], 1)
    V[2 * n] = (0, 0, -1)
    V[2 * n + 1] = (0, 0, 1)
    F = []
    for k in range(n):
        k2 = (k + 1) % n
        if not math.degrees(2 * math.pi * (k + 0.5) / n) < deg:
            F += [(2 * k, 2 * k2, 2 * k2 + 1), (2 * k, 2 * k2 + 1, 2 * k + 1)]
        F += [(2 * n, 2 * k2, 2 * k), (2 * n + 1, 2 * k + 1, 2 * k2 + 1)]
    return V, np.array(F)


@pytest.mark.parametrize("opts,kw", [(["--symmetry", "off"], {"symmetry": False}),
                                     (["--fill-holes", "off"], {"fill_holes": False}),
                                     ([], {"fill_holes": True, "symmetry": True})],
                         ids=["no-symmetry", "no-fill-holes", "defaults"])
def test_pseudo_volume_fill_options_as_soupsign(tmp_path, opts, kw):
    # fill_holes= and symmetry= give soupsign --fill-holes / --symmetry's signs
    V, F = holed_cylinder(70)
    off = str(tmp_path / "c.off")
    with open(off, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(V), len(F)))
        f.writelines("%.17g %.17g %.17g\n" % tuple(v) for v in V)
        f.writelines("3 %d %d %d\n" % tuple(t) for t in F)
    p = str(tmp_path / "s.vti")
    dist = subprocess.Popen([tool("soupdist"), "-q", "-r", "32", off], stdout=subprocess.PIPE)
    subprocess.run([tool("soupsign"), "-q", "--surface", off, "-o", p] + opts,
                   stdin=dist.stdout, check=True)
    assert dist.wait() == 0
    a, _, _ = read_vti(p)
    pv = souptet.pseudo_volume(V, F, resolution=32, **kw)
    assert np.array_equal(pv.values, a)


def test_symmetry_changes_the_holed_cylinder():
    # the fill is used: the signs differ from the caps' alone
    V, F = holed_cylinder(70)
    on = souptet.pseudo_volume(V, F, resolution=32)
    off = souptet.pseudo_volume(V, F, resolution=32, symmetry=False)
    assert not np.array_equal(on.inside, off.inside)
    with pytest.raises(TypeError):
        souptet.pseudo_volume(V, F, 32, True)   # keyword only
