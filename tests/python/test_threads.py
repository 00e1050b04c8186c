# The GIL is released while the library works; Ctrl-C stops a long call.
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import souptet
from conftest import BUNNY, PYDIR


def test_other_threads_run_during_mesh(bunny):
    done = threading.Event()
    out = {}

    def work():
        # meshes until half a second has passed: long enough to tell, however
        # fast one mesh is (a run holding the GIL would let the loop below
        # tick once or twice per mesh, a few times a second)
        t_work = time.monotonic()
        while True:
            out["m"] = souptet.mesh(*bunny, cells=14, tries=1, threads=1)
            if not out["m"].encloses or time.monotonic() - t_work > 0.5:
                break
        done.set()
    t = threading.Thread(target=work)
    t.start()
    ticks = 0
    t0 = time.monotonic()
    while not done.is_set():
        ticks += 1          # pure Python: runs only while the GIL is free
        time.sleep(0.001)
    elapsed = time.monotonic() - t0
    t.join()
    assert out["m"].encloses
    # a tick every 50 ms at least (a loaded machine's sleeps are long; with
    # the GIL held through the run there would be one or two in all)
    assert elapsed > 0.2 and ticks > elapsed * 20, (ticks, elapsed)


def test_progress_from_threads_with_gil(bunny):
    # candidates in parallel: the callable runs on OpenMP threads, one at a time
    seen = set()
    lock = threading.Lock()
    busy = []

    def cb(ev):
        if not lock.acquire(blocking=False):
            busy.append(ev)
        seen.add(threading.get_ident())
        lock.release()
    m = souptet.mesh(*bunny, cells=5, tries=2, threads=2, progress=cb)
    assert m.encloses and not busy and seen


def test_two_threads_mesh_at_once(bunny, bunny_mesh):
    res = [None, None]

    def work(i):
        res[i] = souptet.mesh(*bunny, cells=6, tries=1, threads=1)
    ts = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    [t.start() for t in ts]
    [t.join() for t in ts]
    for r in res:
        assert np.array_equal(r.tets, bunny_mesh.tets)


CHILD = textwrap.dedent("""
    import signal, sys, time
    # as an interactive python3 has it, even when started with SIGINT ignored
    signal.signal(signal.SIGINT, signal.default_int_handler)
    sys.path.insert(0, %(pydir)r)
    import souptet
    V, F = souptet.read(%(bunny)r)
    call = sys.argv[1]
    print("start", flush=True)
    t0 = time.monotonic()
    try:
        if call == "mesh":
            # about 6 s of work (cells 20 took 0.5 s once the fit got
            # faster, and finished before the signal came)
            souptet.mesh(V, F, cells=40, tries=2)
        elif call == "pseudo_volume":
            souptet.pseudo_volume(V, F, resolution=520)
        else:
            souptet.distance(V, F, resolution=700)
        print("finished %%.2f" %% (time.monotonic() - t0), flush=True)
    except KeyboardInterrupt:
        print("interrupted", flush=True)
        # and the module works after it
        souptet.mesh(V[:200], F[(F < 200).all(1)], cells=3, tries=1)
        print("again", flush=True)
""")


@pytest.mark.parametrize("call", ["mesh", "pseudo_volume", "distance"])
def test_ctrl_c(call):
    p = subprocess.Popen([sys.executable, "-c", CHILD % {"pydir": PYDIR, "bunny": BUNNY}, call],
                         stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "start"
    time.sleep(0.5)
    t0 = time.monotonic()
    p.send_signal(signal.SIGINT)
    line = p.stdout.readline().strip()
    dt = time.monotonic() - t0
    rest = p.stdout.read()
    p.wait(timeout=60)
    assert line == "interrupted", line
    assert dt <= 1.5, (dt, line, rest)
    assert "again" in rest and p.returncode == 0


def test_cancel_object_stops_a_run_from_another_thread(bunny):
    # a UI's event loop sets souptet.Cancel while mesh() runs in a worker
    # thread: the library polls the flag itself (progress.h)
    # The flag is set while the run is surely under way: its first
    # "sculpted" event holds the run (the callback waits, GIL released)
    # until this thread has set it, so a fast machine cannot finish the
    # run before the set (a fixed sleep did, once the run got faster).
    c = souptet.Cancel()
    assert not c.is_set()
    out = {}
    under_way, was_set = threading.Event(), threading.Event()

    def hold(ev):
        if ev["what"] == "sculpted" and not under_way.is_set():
            under_way.set()
            was_set.wait(30)

    def work():
        try:
            souptet.mesh(*bunny, cells=30, tries=2, cancel=c, progress=hold)
            out["r"] = "finished"
        except souptet.Cancelled:
            out["r"] = "cancelled"
        out["t"] = time.monotonic()
    t = threading.Thread(target=work)
    t.start()
    assert under_way.wait(60)
    t_set = time.monotonic()
    c.set()
    was_set.set()
    t.join(30)
    assert out.get("r") == "cancelled", out
    # about 0.1 s of work; a loaded machine gets slack (1-1.5 s measured at
    # worst, in the signs' cut of a 240^3 field)
    assert out["t"] - t_set < 3.0, out["t"] - t_set
    assert c.is_set()
    c.clear()
    m = souptet.mesh(*bunny, cells=5, tries=1, cancel=c)
    assert m.encloses and not c.is_set()


def test_cancel_set_before_the_call(bunny):
    c = souptet.Cancel()
    c.set()
    with pytest.raises(souptet.Cancelled):
        souptet.mesh(*bunny, cells=5, tries=1, cancel=c)
    with pytest.raises(TypeError):
        souptet.mesh(*bunny, cells=5, tries=1, cancel=True)
