# Bad input raises a clear exception, never crashes, and the next call works.
import numpy as np
import pytest

import souptet
from conftest import box

V0, F0 = box()


def nan_v():
    V = V0.copy()
    V[3, 1] = np.nan
    return V


def inf_v():
    V = V0.copy()
    V[5, 2] = -np.inf
    return V


def with_f(i, j, x):
    F = F0.copy()
    F[i, j] = x
    return F


BAD = [
    ("nan", lambda: (nan_v(), F0), "V[3]"),
    ("inf", lambda: (inf_v(), F0), "not finite"),
    ("index out of range", lambda: (V0, with_f(4, 1, 8)), "out of range"),
    ("negative index", lambda: (V0, with_f(2, 0, -1)), "negative"),
    ("huge unsigned index", lambda: (V0, with_f(0, 0, 7).astype(np.uint64) + np.uint64(2**63)),
     "out of range"),
    ("V (n, 2)", lambda: (V0[:, :2], F0), "shape"),
    ("V 1-D", lambda: (V0.ravel(), F0), "shape"),
    ("F (m, 4)", lambda: (V0, np.zeros((3, 4), int)), "shape"),
    ("V empty", lambda: (np.zeros((0, 3)), F0), "empty"),
    ("F empty", lambda: (V0, np.zeros((0, 3), int)), "empty"),
    ("V strings", lambda: ([["a", "b", "c"]] * 8, F0), "numbers"),
    ("V ragged", lambda: ([[0, 0], [1, 2, 3]], F0), "V"),
    ("V objects", lambda: (np.array([[object()] * 3] * 8), F0), "numbers"),
    ("V complex", lambda: (V0 + 1j, F0), "numbers"),
    ("V bool", lambda: (V0 > 0, F0), "numbers"),
    ("F floats", lambda: (V0, F0.astype(float)), "integers"),
    ("V None", lambda: (None, F0), "V"),
]


@pytest.mark.parametrize("fn", [souptet.mesh, souptet.pseudo_volume, souptet.distance])
@pytest.mark.parametrize("name,make,msg", BAD, ids=[b[0] for b in BAD])
def test_bad_arrays(fn, name, make, msg):
    V, F = make()
    with pytest.raises(souptet.Error, match=msg.replace("[", r"\[").replace("]", r"\]")):
        fn(V, F)


PARAMS = [
    ({"cells": 0}, "cells"),
    ({"cells": -3}, "cells"),
    ({"cells": 5000}, "cells"),
    ({"cells": 2.5}, "cells"),
    ({"cells": "10"}, "cells"),
    ({"tets": -5}, "tets"),
    ({"tets": 0}, "tets"),
    ({"size": -1.0}, "size"),
    ({"size": 0.0}, "size"),
    ({"size": float("nan")}, "size"),
    ({"size": "big"}, "size"),
    ({"tries": 0}, "tries"),
    ({"seed": -1}, "seed"),
    ({"offset": 0.0}, "offset"),
    ({"offset": float("inf")}, "offset"),
    ({"threads": -1}, "threads"),
]


@pytest.mark.parametrize("kw,msg", PARAMS, ids=[repr(p[0]) for p in PARAMS])
def test_bad_params(kw, msg):
    with pytest.raises(souptet.Error, match=msg):
        souptet.mesh(V0, F0, **kw)


def test_bad_progress():
    with pytest.raises(TypeError):
        souptet.mesh(V0, F0, progress=3)


def test_positional_params_refused():
    with pytest.raises(TypeError):
        souptet.mesh(V0, F0, 10)


@pytest.mark.parametrize("res", [0, -1, 70000])
def test_bad_resolution(res):
    with pytest.raises(souptet.Error, match="resolution"):
        souptet.pseudo_volume(V0, F0, res)
    with pytest.raises(souptet.Error, match="resolution"):
        souptet.distance(V0, F0, res)


def test_bad_band():
    with pytest.raises(souptet.Error, match="band"):
        souptet.distance(V0, F0, band=1.0)


@pytest.mark.parametrize("fn", [souptet.mesh, souptet.pseudo_volume, souptet.distance])
def test_soup_without_extent_is_error(fn):
    with pytest.raises(souptet.Error, match="no extent"):
        fn(np.ones((3, 3)), [[0, 1, 2]])


def test_next_call_works_after_errors():
    for name, make, msg in BAD:
        with pytest.raises(souptet.Error):
            souptet.mesh(*make())
    m = souptet.mesh(V0, F0, cells=3, tries=1)
    assert m.encloses and len(m.tets) > 0


def test_out_of_memory_is_memoryerror():
    # under a 1 GiB address-space limit a 2 GiB field cannot be had
    import subprocess
    import sys
    from conftest import BUNNY, PYDIR
    code = """
import resource, sys
sys.path.insert(0, %r)
import souptet
V, F = souptet.read(%r)
resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))
try:
    souptet.distance(V, F, resolution=900)
    print('no error')
except MemoryError as e:
    print('MemoryError', e)
print(len(souptet.mesh(V, F, cells=3, tries=1).tets) > 0)
""" % (PYDIR, BUNNY)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.stdout.startswith("MemoryError out of memory"), (r.stdout, r.stderr)
    assert r.stdout.strip().endswith("True")


def test_lattice_over_memory_is_error():
    with pytest.raises(souptet.Error, match="over 80% of this machine's memory"):
        souptet.mesh(V0, F0, cells=4096, tries=1024)
