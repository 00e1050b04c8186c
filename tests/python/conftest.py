# tests/python/conftest.py - fixtures for the Python module's tests, and a
# TAP line per test into $SOUPTET_TAP when set (tests/tools/python.t).
import os
import sys

import numpy as np
import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BIN = os.environ.get("SOUPTET_BIN", os.path.join(ROOT, "build", "bin"))
PYDIR = os.environ.get("SOUPTET_PYTHON", os.path.join(os.path.dirname(BIN), "python"))
if PYDIR not in sys.path:
    sys.path.insert(0, PYDIR)
BUNNY = os.path.join(ROOT, "corpus", "bunny.obj")


def tool(name):
    return os.path.join(BIN, name)


def box(lo=(0.0, 0.0, 0.0), hi=(1.0, 1.0, 1.0)):
    """A closed, outward box as (V, F): 8 vertices, 12 triangles."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    V = np.array([[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
                  [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]], float)
    F = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                  [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])
    return V, F


@pytest.fixture(scope="session")
def bunny():
    import souptet
    return souptet.read(BUNNY)


@pytest.fixture(scope="session")
def bunny_mesh(bunny):
    import souptet
    return souptet.mesh(*bunny, cells=6, tries=1)


_tap = {"n": 0, "fp": None}


def pytest_configure(config):
    path = os.environ.get("SOUPTET_TAP")
    if path:
        _tap["fp"] = open(path, "w", buffering=1)


def pytest_runtest_logreport(report):
    fp = _tap["fp"]
    if fp is None:
        return
    # one line per test: its call phase, or the phase that failed or skipped
    if report.when == "call" or (report.when == "setup" and not report.passed) or \
            (report.when == "teardown" and report.failed):
        _tap["n"] += 1
        name = report.nodeid.split("::", 1)[-1]
        if report.skipped:
            fp.write("ok %d - %s # SKIP %s\n" % (_tap["n"], name,
                                                 str(report.longrepr[-1]) if isinstance(report.longrepr, tuple) else ""))
        elif hasattr(report, "wasxfail"):
            fp.write("ok %d - %s # TODO %s\n" % (_tap["n"], name, report.wasxfail))
        else:
            fp.write("%s %d - %s%s\n" % ("ok" if report.passed else "not ok", _tap["n"], name,
                                         "" if report.passed else " (%s)" % report.when))
            if report.failed:
                for line in str(report.longrepr).splitlines()[-15:]:
                    fp.write("#   %s\n" % line)


def pytest_unconfigure(config):
    if _tap["fp"]:
        _tap["fp"].close()
