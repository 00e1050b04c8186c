"""Stage "scale" (issue 23): how soupmesh's time and memory grow.

Two tables, each with the exponent of a least-squares fit of log(cost)
against log(size):

  - against the triangle count: the dragon's decimations (dragon_res3,
    dragon_res2), the dragon itself, and soups made of k transformed copies
    of it (each copy rotated about its own axis and moved to its own place in
    a row, written as one binary PLY): k = 4 by default beside the others,
    SOUPTET_BENCH_SCALE_COPIES="4 12" for more (12 copies: 10.5 million
    triangles, minutes and a few GB);
  - against --cells (5 10 20 40 by default, SOUPTET_BENCH_SCALE_CELLS) on
    dragon_res2.

The copies are written once and reused: into SOUPTET_BENCH_SCALE_DIR
when set (a folder kept between runs, e.g. /tmp/souptet-scale: the 12
copies are 199 MB and take minutes to write), else into the results' tmp
folder.

SOUPTET_BENCH_SCALE_MODELS picks the corpus models of the first table,
SOUPTET_BENCH_SCALE_PEER the OpenVDB repeats (0: none).

Every row is `soupmesh --tries 1` under /usr/bin/time (wall clock, CPU
seconds user + sys, peak RSS), with soupmesh -v's stage times (distance, signs, candidates), the tets
and whether the mesh encloses the input. The dragon's row also runs
OpenVDB's meshToUnsignedDistanceField at 256^3 (bench/vdb_dist: the whole
process, reading the soup and writing the .vdb, as soupdist -r 256 beside
it does), soupdist and `soupmesh -q` --tries 1 and --tries 4, alternating,
median of 3 (issue 23's targets; -q because -v adds work a user's run does
not do: the input -> boundary distance and per-iteration statistics).

On a shared machine the wall clock is mostly the other jobs: the CPU
seconds (the soupdist / OpenVDB ratio by CPU too) and the load average at
the stage's start and end are in the tables for that.
"""
import math
import os
import re
import struct
import sys

COPIES = tuple(int(k) for k in os.environ.get("SOUPTET_BENCH_SCALE_COPIES", "4").split())
CELLS = tuple(int(c) for c in os.environ.get("SOUPTET_BENCH_SCALE_CELLS", "5 10 20 40").split())
TRI_MODELS = tuple(os.environ.get("SOUPTET_BENCH_SCALE_MODELS",
                                  "dragon_res3 dragon_res2 dragon").split())
CELLS_MODEL = "dragon_res2"
PEER_RES = 256
PEER_REPEAT = int(os.environ.get("SOUPTET_BENCH_SCALE_PEER", "3"))   # 0: no OpenVDB rows


def _log(msg):
    sys.stderr.write("bench: scale: %s\n" % msg)


def read_ply_ascii(path):
    """(vertices [(x, y, z)], faces [(a, b, c)]) of an ASCII PLY of
    triangles (the dragon's files)."""
    with open(path) as f:
        nv = nf = 0
        for line in f:
            w = line.split()
            if w[:2] == ["element", "vertex"]:
                nv = int(w[2])
            elif w[:2] == ["element", "face"]:
                nf = int(w[2])
            elif w and w[0] == "end_header":
                break
        verts = [tuple(float(x) for x in next(f).split()[:3]) for _ in range(nv)]
        faces = []
        for _ in range(nf):
            w = next(f).split()
            if w[0] != "3":
                raise ValueError("%s: not a triangle: %s" % (path, " ".join(w)))
            faces.append((int(w[1]), int(w[2]), int(w[3])))
    return verts, faces


def write_copies(src, k, out):
    """k copies of the soup in src as one binary PLY: copy i rotated by
    i * 30 degrees about z and by i * 45 degrees about x, then moved along x
    by 1.1 times the model's diagonal per copy (apart, so the soup has k
    pieces and k times the triangles in a box k times as long)."""
    verts, faces = read_ply_ascii(src)
    lo = [min(v[a] for v in verts) for a in range(3)]
    hi = [max(v[a] for v in verts) for a in range(3)]
    c = [(lo[a] + hi[a]) / 2 for a in range(3)]
    diag = math.sqrt(sum((hi[a] - lo[a]) ** 2 for a in range(3)))
    nv = len(verts)
    with open(out + ".tmp", "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
                 "property float x\nproperty float y\nproperty float z\n"
                 "element face %d\nproperty list uchar int vertex_indices\n"
                 "end_header\n" % (k * nv, k * len(faces))).encode())
        pv = struct.Struct("<fff")
        for i in range(k):
            az, ax = math.radians(30 * i), math.radians(45 * i)
            cz, sz, cx, sx = math.cos(az), math.sin(az), math.cos(ax), math.sin(ax)
            buf = bytearray()
            for v in verts:
                x, y, z = v[0] - c[0], v[1] - c[1], v[2] - c[2]
                x, y = cz * x - sz * y, sz * x + cz * y
                y, z = cx * y - sx * z, sx * y + cx * z
                buf += pv.pack(x + 1.1 * diag * i, y, z)
            f.write(buf)
        pf = struct.Struct("<Biii")
        for i in range(k):
            o = i * nv
            buf = bytearray()
            for a, b, d in faces:
                buf += pf.pack(3, a + o, b + o, d + o)
            f.write(buf)
    os.replace(out + ".tmp", out)


def mesh_row(bench, build, path, cells, out):
    r = bench.run(["/usr/bin/time", "-f", "WALL %e CPU %U %S RSS %M",
                   os.path.join(build, "bin", "soupmesh"), "-v", "--tries", "1",
                   "--cells", str(cells), "--threads", str(bench.THREADS), "-o", out, path])
    if r.returncode not in (0, 3):
        raise RuntimeError("soupmesh failed on %s: %s" % (path, r.stderr[-2000:]))
    e = r.stderr
    m = re.search(r"WALL ([0-9.]+) CPU ([0-9.]+) ([0-9.]+) RSS (\d+)", e)
    row = {"seconds": float(m.group(1)), "cpu_s": float(m.group(2)) + float(m.group(3)),
           "rss_mib": int(m.group(4)) / 1024.0, "encloses": r.returncode == 0}
    m = re.search(r"(\d+) vertices, (\d+) triangles", e)
    row["triangles"] = int(m.group(2))
    m = re.search(r"distance ([0-9.]+) s, signs ([0-9.]+) s(?: \([^)]*\))?, \d+ candidates? ([0-9.]+) s", e)
    if m:
        row["distance_s"], row["signs_s"], row["candidates_s"] = (float(x) for x in m.groups())
    m = re.search(r"field (\d+)x(\d+)x(\d+)", e)
    row["voxels"] = int(m.group(1)) * int(m.group(2)) * int(m.group(3)) if m else 0
    m = re.search(r"(\d+) tets, (\d+) points, dihedral ([0-9.]+)\.\.([0-9.]+)", e)
    if m:
        row["tets"] = int(m.group(1))
        row["min_dihedral"] = float(m.group(3))
        row["max_dihedral"] = float(m.group(4))
    return row


def fit_exponent(xs, ys):
    """Slope of the least-squares line through (log x, log y)."""
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if x > 0 and y > 0]
    if len(pts) < 2:
        return float("nan")
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx if sxx > 0 else float("nan")


def quiet_run(bench, build, path, tries, out):
    """Wall seconds and peak MiB of `soupmesh -q --tries N` at 10 cells: the
    run a user makes, without -v's extra work (the input -> boundary
    distance, per-iteration statistics)."""
    r = bench.run(["/usr/bin/time", "-f", "WALL %e RSS %M",
                   os.path.join(build, "bin", "soupmesh"), "-q", "--tries", str(tries),
                   "--cells", "10", "--threads", str(bench.THREADS), "-o", out, path])
    if r.returncode not in (0, 3):
        raise RuntimeError("soupmesh failed on %s: %s" % (path, r.stderr[-2000:]))
    m = re.search(r"WALL ([0-9.]+) RSS (\d+)", r.stderr)
    return float(m.group(1)), int(m.group(2)) / 1024.0


def whole_run(bench, cmd):
    """(wall seconds, CPU seconds user + sys) of a whole process (start,
    reading and writing count)."""
    r = bench.run(["/usr/bin/time", "-f", "WALL %e CPU %U %S"] + cmd)
    if r.returncode != 0:
        raise RuntimeError("%s failed: %s" % (cmd[0], r.stderr[-2000:]))
    m = re.findall(r"WALL ([0-9.]+) CPU ([0-9.]+) ([0-9.]+)", r.stderr)[-1]
    return float(m[0]), float(m[1]) + float(m[2])


def peer_ratios(bench, build, model, tmp):
    """soupdist -r 256 and OpenVDB's distance at 256^3 as whole processes
    doing the same job (bench/vdb_dist: read, distance, write the .vdb),
    and soupmesh -q --tries 1 and --tries 4, alternating, median of
    PEER_REPEAT each."""
    peer = os.path.join(build, "bench", "vdb_dist")
    if not os.path.exists(peer) or PEER_REPEAT < 1:
        return None
    ref = os.path.join(tmp, "scale-ref.vdb")
    out = os.path.join(tmp, "scale-peer.vtu")
    sd, vd, sm, s4, rss = [], [], [], [], []
    for _ in range(PEER_REPEAT):
        sd.append(whole_run(bench, [os.path.join(build, "bin", "soupdist"), "-q", "-r", str(PEER_RES),
                                    "--threads", str(bench.THREADS), "-o", ref, model]))
        vd.append(whole_run(bench, [peer, model, "-r", str(PEER_RES),
                                    "--threads", str(bench.THREADS), "-o", ref]))
        w, m = quiet_run(bench, build, model, 1, out)
        sm.append(w)
        rss.append(m)
        s4.append(quiet_run(bench, build, model, 4, out)[0])
    med = lambda v: sorted(v)[len(v) // 2]
    sd_cpu, vd_cpu = med([x[1] for x in sd]), med([x[1] for x in vd])
    sd, vd = [x[0] for x in sd], [x[0] for x in vd]
    return {"soupdist_s": med(sd), "openvdb_s": med(vd), "soupmesh_s": med(sm),
            "soupdist_cpu_s": sd_cpu, "openvdb_cpu_s": vd_cpu,
            "soupdist_cpu_ratio": sd_cpu / vd_cpu,
            "soupmesh_tries4_s": med(s4), "soupmesh_rss_mib": max(rss),
            "soupdist_ratio": med(sd) / med(vd), "soupmesh_ratio": med(sm) / med(vd),
            "tries4_ratio": med(s4) / med(sm)}


def load_average():
    """The 1, 5 and 15 minute load averages, as text."""
    try:
        return "%.2f %.2f %.2f" % os.getloadavg()
    except OSError:
        return "unknown"


def stage(build, bench):
    load_start = load_average()
    tmp = os.path.join(bench.RESULTS, "tmp")
    os.makedirs(tmp, exist_ok=True)
    tri_rows, cell_rows = [], []
    inputs = [(m, bench.model_path(m)) for m in TRI_MODELS]
    dragon = bench.model_path("dragon") if COPIES or PEER_REPEAT > 0 else None
    copies_dir = os.environ.get("SOUPTET_BENCH_SCALE_DIR") or tmp
    if COPIES:
        os.makedirs(copies_dir, exist_ok=True)
    for k in COPIES:
        p = os.path.join(copies_dir, "dragon_x%d.ply" % k)   # generated: not in the corpus cache
        if not os.path.exists(p) and dragon:
            _log("writing %d copies of the dragon to %s" % (k, p))
            write_copies(dragon, k, p)
        inputs.append(("dragon_x%d" % k, p))
    for name, path in inputs:
        if not path:
            continue
        _log("%s at 10 cells" % name)
        row = mesh_row(bench, build, path, 10, os.path.join(tmp, "scale.vtu"))
        row["model"] = name
        tri_rows.append(row)
    cm = bench.model_path(CELLS_MODEL)
    for c in CELLS:
        _log("%s at %d cells" % (CELLS_MODEL, c))
        row = mesh_row(bench, build, cm, c, os.path.join(tmp, "scale.vtu"))
        row["model"], row["cells"] = CELLS_MODEL, c
        cell_rows.append(row)
    peer = peer_ratios(bench, build, dragon, tmp) if dragon else None
    load_end = load_average()

    md = ["# soupmesh cost growth (issue 23)", "",
          "`soupmesh --tries 1 --threads %d`, wall clock, CPU seconds (user + sys) and peak "
          "RSS (/usr/bin/time). Load average (1, 5, 15 min) at the start %s, at the end %s "
          "(%d cores)." % (bench.THREADS, load_start, load_end, os.cpu_count() or 0),
          "", "## Against the triangle count (--cells 10)", "",
          "| model | triangles | voxels | tets | min..max dihedral | encloses | distance s | signs s | candidates s | total s | CPU s | peak MiB |",
          "|---|---:|---:|---:|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in tri_rows:
        md.append("| %s | %d | %d | %d | %.1f..%.1f | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f |" % (
            r["model"], r["triangles"], r["voxels"], r.get("tets", 0), r.get("min_dihedral", 0),
            r.get("max_dihedral", 0), "yes" if r["encloses"] else "NO", r.get("distance_s", 0),
            r.get("signs_s", 0), r.get("candidates_s", 0), r["seconds"], r["cpu_s"], r["rss_mib"]))
    xs = [r["triangles"] for r in tri_rows]
    md += ["", "Fitted exponent (cost ~ triangles^e): time %.2f, peak memory %.2f, "
           "distance %.2f, signs %.2f, candidates %.2f." % (
               fit_exponent(xs, [r["seconds"] for r in tri_rows]),
               fit_exponent(xs, [r["rss_mib"] for r in tri_rows]),
               fit_exponent(xs, [r.get("distance_s", 0) for r in tri_rows]),
               fit_exponent(xs, [r.get("signs_s", 0) for r in tri_rows]),
               fit_exponent(xs, [r.get("candidates_s", 0) for r in tri_rows])),
           "", "## Against --cells (%s)" % CELLS_MODEL, "",
           "| cells | voxels | tets | min..max dihedral | encloses | distance s | signs s | candidates s | total s | CPU s | peak MiB |",
           "|---:|---:|---:|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in cell_rows:
        md.append("| %d | %d | %d | %.1f..%.1f | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f |" % (
            r["cells"], r["voxels"], r.get("tets", 0), r.get("min_dihedral", 0),
            r.get("max_dihedral", 0), "yes" if r["encloses"] else "NO", r.get("distance_s", 0),
            r.get("signs_s", 0), r.get("candidates_s", 0), r["seconds"], r["cpu_s"], r["rss_mib"]))
    cs = [r["cells"] for r in cell_rows]
    md += ["", "Fitted exponent (cost ~ cells^e): time %.2f, peak memory %.2f; "
           "time against tets %.2f, against voxels %.2f." % (
               fit_exponent(cs, [r["seconds"] for r in cell_rows]),
               fit_exponent(cs, [r["rss_mib"] for r in cell_rows]),
               fit_exponent([r.get("tets", 0) for r in cell_rows], [r["seconds"] for r in cell_rows]),
               fit_exponent([r["voxels"] for r in cell_rows], [r["seconds"] for r in cell_rows]))]
    if peer:
        md += ["", "## Beside OpenVDB (the dragon, alternating, median of %d)" % PEER_REPEAT, "",
               "Whole processes. soupdist -r %d: %.2f s; OpenVDB meshToUnsignedDistanceField at %d^3 "
               "(bench/vdb_dist, reading and writing as soupdist): %.2f s "
               "(ratio %.2f, target <= 0.5; by CPU seconds %.2f / %.2f: %.2f); soupmesh -q --tries 1: %.2f s (ratio %.2f, target <= 1.5), "
               "peak %.0f MiB (target <= 400); --tries 4: %.2f s (%.2f x --tries 1, target <= 2)." % (
                   PEER_RES, peer["soupdist_s"], PEER_RES, peer["openvdb_s"], peer["soupdist_ratio"],
                   peer["soupdist_cpu_s"], peer["openvdb_cpu_s"], peer["soupdist_cpu_ratio"],
                   peer["soupmesh_s"], peer["soupmesh_ratio"], peer["soupmesh_rss_mib"],
                   peer["soupmesh_tries4_s"], peer["tries4_ratio"])]
    rows = {"triangles": tri_rows, "cells": cell_rows, "openvdb": peer}
    return rows, "\n".join(md) + "\n"
