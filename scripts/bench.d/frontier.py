"""Stage "frontier" (issue 18, item 3): souptet against the only peer that
also encloses, CGAL's 3D alpha wrap followed by TetGen, at matched tet
counts (TARGETS), on every axis at once: min and max dihedral angle, both
distances, enclosure, time.

  souptet     `soupmesh --tets N` with its defaults otherwise (--tries 1,
              --offset 0.4; --offset-best-effort so a mesh that misses the
              offset is still measured), --threads 2
  wrap+TetGen bench/alpha_wrap (CGAL alpha_wrap_3, offset alpha/30 as in
              scripts/bench.d/sim.py) then `tetgen -pq` on the wrap; alpha
              searched (up to SEARCH runs, from diag/12, stepping by the
              count's measured growth in alpha, as sim.py does with a fixed
              exponent, bisecting once the target is bracketed) for the count
              within 20% of N; the closest wins and a miss is reported with
              what it reached

Both meshes are measured by `tetstat --json --surface S MESH` (TetGen's
.node/.ele read as they are), S the input: boundary -> S (the farthest
boundary vertex from S, Cetra's condition) and S -> boundary (the farthest
point of S from the boundary, sampled at S's vertices and four points per
triangle: how far the cage bulges or cuts corners), relative to S's box
diagonal and in h, souptet's lattice cell width of the souptet mesh at the
same target (the peer has no h; its distances are divided by souptet's);
enclosure as tetstat decides it (exact: every vertex of S in the mesh, no
triangle of S crossing its boundary, conforming, no inverted tet). Times
are wall seconds of the whole runs: soupmesh (read, field, signs, the
--tets size search, fit); alpha_wrap + tetgen for the alpha that won
(the search's total beside it).

At SWEEP_TARGET the peer also runs with its other settings (VARIANTS: a
larger offset, tetgen -pqY keeping the wrap as the boundary, -pq1.2/15
asking for 15-degree dihedral angles), each with its own alpha search: the
settings it could trade distance for angles with; every such mesh is marked
dominated by souptet's (souptet at least as good on min and max dihedral,
b->S and S->b, better on one), dominating it, or a trade. Besides
tetstat's b->S (boundary vertices), b->S over 7 points of every boundary
face (bench/alpha_wrap distance, floating point), which sees a wrap
triangle bridging a concavity between vertices that lie on the offset.

Pictures: bench/results/frontier-plot.png (matplotlib: min dihedral against
max(b->S faces, S->b) per model), and bench/results/frontier.png, souptet
beside the peer at RENDER_TARGET on RENDER_MODEL coloured by each tet's min
dihedral (scripts/render-frontier.py under xvfb-run).

SOUPTET_BENCH_MODELS="bunny fandisk" runs only these models (names as in
MODELS). Needs $(BUILD)/bench/alpha_wrap (make bench builds it) and tetgen.
"""
import json
import math
import os
import shutil
import subprocess
import sys
import time

# (name, input): clean models from corpus/cache/models, damaged ones from
# corpus/cache/damaged.
MODELS = (("bunny", "bunny"), ("armadillo", "armadillo"), ("elephant", "elephant"),
          ("fandisk", "fandisk"), ("couplingdown", "couplingdown"),
          ("fandisk-interpenetrating", "damaged:fandisk-interpenetrating"))
TARGETS = (500, 1500, 5000)
THREADS = 2
SEARCH = 8                       # alpha_wrap + tetgen runs per target at most
TOLERANCE = 0.2                  # a matched count is within 20% of the target
OFFSET_OF_ALPHA = 1.0 / 30       # as scripts/bench.d/sim.py
TIMEOUT = 600
RENDER_MODEL, RENDER_TARGET = "bunny", 1500
# The peer's other settings, at SWEEP_TARGET only: (offset / alpha, tetgen
# flags). -pqY keeps the wrap as the boundary (no Steiner point on it);
# -pq1.2/15 asks TetGen for radius-edge 1.2 and dihedral angles of 15 degrees
# at least; a larger offset rounds the wrap.
SWEEP_TARGET = 1500
VARIANTS = ((1.0 / 30, "-pqY"), (1.0 / 10, "-pq"), (1.0 / 3, "-pq"), (1.0 / 3, "-pq1.2/15"))
ONLY = os.environ.get("SOUPTET_BENCH_MODELS", "").split()


def _log(msg):
    sys.stderr.write("bench: frontier: %s\n" % msg)


def _input(bench, spec):
    if spec.startswith("damaged:"):
        p = os.path.join(bench.DAMAGED, spec[len("damaged:"):] + ".off")
        return p if os.path.exists(p) else None
    return bench.model_path(spec)


def _tetstat(bench, build, mesh, surface):
    r = bench.run([os.path.join(build, "bin", "tetstat"), "--json", "-q", "--threads",
                   str(THREADS), "--surface", surface, mesh], timeout=TIMEOUT)
    if r.returncode != 0:
        raise RuntimeError("tetstat %s: %s" % (os.path.basename(mesh), r.stderr.strip()[-200:]))
    d = json.loads(r.stdout)
    s = d["surface"]
    return {"tets": d["tets"], "points": d["points"], "min_dihedral": d["min_dihedral"],
            "max_dihedral": d["max_dihedral"], "inverted": d["inverted"],
            "conforming": d["conforming"], "h": d.get("h"),
            "diagonal": s["diagonal"], "dist_max": s["dist_max"],
            "dist_max_diag": s["dist_max_diag"], "surface_dist_max": s["surface_dist_max"],
            "surface_dist_max_diag": s["surface_dist_max_diag"],
            "fraction_inside": s["fraction_inside"],
            "crossing_triangles": s["crossing_triangles"], "encloses": s["encloses"],
            "enclosure": s["enclosure"]}


def _read_mesh(path):
    """(points, tets) as numpy arrays of a .vtu or of TetGen's .node/.ele
    (given the .ele)."""
    import numpy as np
    if path.endswith(".ele"):
        def rows(fn):
            with open(fn) as f:
                for line in f:
                    line = line.split("#")[0].split()
                    if line:
                        yield line
        r = rows(path[:-4] + ".node")
        n = int(next(r)[0])
        node = [next(r) for _ in range(n)]
        base = int(node[0][0])
        pts = np.array([[float(x) for x in q[1:4]] for q in node])
        r = rows(path)
        m = int(next(r)[0])
        tets = np.array([[int(x) for x in next(r)[1:5]] for _ in range(m)], dtype=np.int64) - base
        return pts, tets
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    rd = vtk.vtkXMLUnstructuredGridReader()
    rd.SetFileName(path)
    rd.Update()
    g = rd.GetOutput()
    pts = vtk_to_numpy(g.GetPoints().GetData()).astype(np.float64)
    conn = vtk_to_numpy(g.GetCells().GetConnectivityArray()).astype(np.int64)
    return pts, conn.reshape(-1, 4)


def _boundary_face_dist(bench, build, mesh, src, work):
    """The farthest of the boundary's sample points from S: every boundary
    face's corners, centroid and the midpoints between the centroid and the
    corners (the points tetstat samples S at, here on the mesh's side), by
    alpha_wrap distance (CGAL's AABB tree, floating point). None when
    alpha_wrap fails."""
    import numpy as np
    pts, tets = _read_mesh(mesh)
    faces = np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 2, 3]], tets[:, [0, 1, 3]],
                            tets[:, [0, 1, 2]]])
    key = np.sort(faces, axis=1)
    _, first, count = np.unique(key, axis=0, return_index=True, return_counts=True)
    bf = faces[first[count == 1]]
    a, b, c = pts[bf[:, 0]], pts[bf[:, 1]], pts[bf[:, 2]]
    g = (a + b + c) / 3
    samp = np.stack([a, b, c, g, (g + a) / 2, (g + b) / 2, (g + c) / 2], axis=1).reshape(-1, 3)
    off = os.path.join(work, "wsamples.off")
    nb = len(bf)
    with open(off, "w") as f:
        f.write("OFF\n%d %d 0\n" % (7 * nb, 3 * nb))
        for q in samp:
            f.write("%.17g %.17g %.17g\n" % tuple(q))
        for i in range(nb):
            o = 7 * i
            f.write("3 %d %d %d\n3 %d %d %d\n3 %d %d %d\n" % (
                o, o + 1, o + 2, o + 3, o + 4, o + 5, o + 5, o + 6, o + 3))
    r = bench.run([os.path.join(build, "bench", "alpha_wrap"), "distance", off, src],
                  timeout=TIMEOUT)
    os.remove(off)
    if r.returncode != 0:
        return None
    return json.loads(r.stdout)["max"]


def _souptet(bench, build, src, target, out):
    cmd = [os.path.join(build, "bin", "soupmesh"), "-q", "--offset-best-effort",
           "--threads", str(THREADS), "--tets", str(target), "-o", out, src]
    t0 = time.time()
    r = bench.run(cmd, timeout=TIMEOUT)
    secs = time.time() - t0
    if r.returncode != 0 or not os.path.exists(out):
        raise RuntimeError("soupmesh: " + r.stderr.strip()[-200:])
    return secs, "soupmesh --tets %d --threads %d" % (target, THREADS)


def _ele_count(path):
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#"):
                return int(line.split()[0])
    return 0


def _wrap_tetgen(bench, build, src, alpha, offset, work, stem, flags="-pq"):
    """alpha_wrap then tetgen FLAGS; (tets, seconds, wrap faces), the mesh in
    work/stem.1.node/.ele, the wrap in work/stem.off."""
    off = os.path.join(work, stem + ".off")
    t0 = time.time()
    r = bench.run([os.path.join(build, "bench", "alpha_wrap"), "wrap", src, off,
                   "%.17g" % alpha, "%.17g" % offset], timeout=TIMEOUT)
    if r.returncode != 0:
        raise RuntimeError("alpha_wrap: " + r.stderr.strip()[-200:])
    faces = json.loads(r.stdout)["faces"]
    r = bench.run(["tetgen", flags + "Q", off], timeout=TIMEOUT)
    secs = time.time() - t0
    ele = os.path.join(work, stem + ".1.ele")
    if r.returncode != 0 or not os.path.exists(ele):
        raise RuntimeError("tetgen %s: " % flags + (r.stderr or r.stdout).strip()[-200:])
    for ext in (".1.face", ".1.edge", ".1.smesh"):
        if os.path.exists(os.path.join(work, stem + ext)):
            os.remove(os.path.join(work, stem + ext))
    return _ele_count(ele), secs, faces


def _peer(bench, build, src, target, diag, work, start, ratio=OFFSET_OF_ALPHA, flags="-pq"):
    """Search alpha (offset = ratio alpha, then tetgen FLAGS) for target
    tets. Returns (best, tries): best a dict with alpha, offset, tets,
    seconds, faces, stem; tries the (alpha/diag, tets) of every run. start:
    (alpha, tets) pairs already seen with these settings, to begin from the
    nearest."""
    tries, runs = [], []
    seen = sorted(start, key=lambda at: abs(math.log(at[1] / target)))
    alpha = diag / 12.0
    k = 2.0                       # tets ~ alpha^-k (sim.py's fixed exponent)
    if seen:
        alpha = seen[0][0] * (seen[0][1] / target) ** (1.0 / k)
    for i in range(SEARCH):
        stem = "w%d" % i
        try:
            n, secs, faces = _wrap_tetgen(bench, build, src, alpha, alpha * ratio,
                                          work, stem, flags)
        except (RuntimeError, subprocess.TimeoutExpired) as e:
            tries.append({"alpha_rel": alpha / diag, "error": str(e)[:200]})
            break
        if n == 0:
            tries.append({"alpha_rel": alpha / diag, "error": "tetgen %s: 0 tets" % flags})
            break
        runs.append({"alpha": alpha, "offset": alpha * ratio, "tets": n,
                     "seconds": secs, "faces": faces, "stem": stem})
        tries.append({"alpha_rel": alpha / diag, "tets": n, "seconds": secs})
        _log("  alpha diag/%.4g: %d tets (%.1f s)" % (diag / alpha, n, secs))
        if abs(n - target) <= TOLERANCE * target * 0.5:
            break                 # within 10%: good enough, stop early
        pts = sorted(runs, key=lambda r: abs(math.log(r["tets"] / target)))[:2]
        if len(pts) == 2 and pts[0]["alpha"] != pts[1]["alpha"] and pts[0]["tets"] != pts[1]["tets"]:
            k = -math.log(pts[0]["tets"] / pts[1]["tets"]) / math.log(pts[0]["alpha"] / pts[1]["alpha"])
            k = min(max(k, 0.5), 4.0)
        b = pts[0]
        nxt = b["alpha"] * (b["tets"] / target) ** (1.0 / k)
        # The count need not fall monotonically with alpha (TetGen's
        # refinement): between the largest alpha that gave too many tets and
        # the smallest that gave too few, halve the bracket (geometrically)
        # when the step leaves it.
        over = [r["alpha"] for r in runs if r["tets"] > target]
        under = [r["alpha"] for r in runs if r["tets"] < target]
        if over and under and max(over) < min(under) and not max(over) < nxt < min(under):
            nxt = math.sqrt(max(over) * min(under))
        if any(abs(nxt / r["alpha"] - 1) < 1e-3 for r in runs):
            break
        alpha = nxt
    if not runs:
        return None, tries
    # A run within the tolerance wins over any outside it, then the closest.
    best = min(runs, key=lambda r: (abs(r["tets"] - target) > TOLERANCE * target,
                                    abs(math.log(r["tets"] / target))))
    best["search_seconds"] = sum(r["seconds"] for r in runs)
    return best, tries


def _clean(work):
    for f in os.listdir(work):
        if f.startswith("w"):
            os.remove(os.path.join(work, f))


def _peer_row(bench, build, src, target, diag, work, seen, s, ratio=OFFSET_OF_ALPHA,
              flags="-pq", start=None):
    """The peer at target tets with offset = ratio alpha and tetgen FLAGS,
    measured: (row, best run). seen grows by this search's runs."""
    first = list(seen) if seen or start is None else [(start, target)]
    best, tries = _peer(bench, build, src, target, diag, work, first, ratio, flags)
    seen += [(t["alpha_rel"] * diag, t["tets"]) for t in tries if "tets" in t]
    p = {"search": tries, "offset_of_alpha": ratio, "tetgen": flags}
    if best is None:
        p["error"] = tries[-1].get("error", "no run") if tries else "no run"
        _log("%s %d peer (alpha/%g, %s): %s" % (os.path.basename(src), target, 1 / ratio, flags,
                                                  p["error"]))
        return p, None
    ele = os.path.join(work, best["stem"] + ".1.ele")
    try:
        p.update(_tetstat(bench, build, ele, src))
    except (RuntimeError, subprocess.TimeoutExpired) as e:
        p["error"] = str(e)[:200]
        return p, best
    p.update({"seconds": best["seconds"], "search_seconds": best["search_seconds"],
              "alpha_rel": best["alpha"] / diag, "offset_rel": best["offset"] / diag,
              "wrap_faces": best["faces"],
              "matched": abs(best["tets"] - target) <= TOLERANCE * target,
              "how": "alpha = diag/%.4g, offset = alpha/%g; tetgen %s" % (
                  diag / best["alpha"], 1 / ratio, flags)})
    # The wrap's own vertices to S (alpha_wrap distance): where its offset
    # puts them, before TetGen adds Steiner points on its triangles.
    r = bench.run([os.path.join(build, "bench", "alpha_wrap"), "distance",
                   os.path.join(work, best["stem"] + ".off"), src], timeout=TIMEOUT)
    if r.returncode == 0:
        p["wrap_vertices_dist_max_diag"] = json.loads(r.stdout)["max"] / diag
    fd = _boundary_face_dist(bench, build, ele, src, work)
    p["faces_dist_max_diag"] = fd / diag if fd is not None else None
    if s.get("h"):
        p["dist_max_h_souptet"] = p["dist_max"] / s["h"]
        p["surface_dist_max_h_souptet"] = p["surface_dist_max"] / s["h"]
    _log("%s %d peer (alpha/%g, %s): %d tets, %.1f/%.1f deg, %.3f/%.3f diag, %s, %.1f s" % (
        os.path.basename(src), target, 1 / ratio, flags, p["tets"], p["min_dihedral"],
        p["max_dihedral"], p["dist_max_diag"], p["surface_dist_max_diag"], p["enclosure"],
        p["seconds"]))
    return p, best


def stage(build, bench):
    work = os.path.join(bench.RESULTS, "tmp-frontier")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    rows = []
    render = None
    for name, spec in MODELS:
        if ONLY and name not in ONLY:
            continue
        src = _input(bench, spec)
        if not src:
            _log("%s: no input" % name)
            continue
        seen = []                 # (alpha, tets) of the peer on this model
        for target in TARGETS:
            row = {"model": name, "input": os.path.basename(src), "target": target}
            out = os.path.join(work, "s-%s-%d.vtu" % (name, target))
            try:
                secs, how = _souptet(bench, build, src, target, out)
                s = _tetstat(bench, build, out, src)
                s.update({"seconds": secs, "how": how})
                fd = _boundary_face_dist(bench, build, out, src, work)
                s["faces_dist_max_diag"] = fd / s["diagonal"] if fd is not None else None
            except (RuntimeError, subprocess.TimeoutExpired) as e:
                s = {"error": str(e)[:200]}
            row["souptet"] = s
            if "error" not in s:
                _log("%s %d souptet: %d tets, %.1f/%.1f deg, %.3f/%.3f diag, %s, %.1f s" % (
                    name, target, s["tets"], s["min_dihedral"], s["max_dihedral"],
                    s["dist_max_diag"], s["surface_dist_max_diag"], s["enclosure"], secs))
                diag = s["diagonal"]
            else:
                _log("%s %d souptet: %s" % (name, target, s["error"]))
                diag = None
            p = {}
            if diag:
                p, best = _peer_row(bench, build, src, target, diag, work, seen, s)
                if name == RENDER_MODEL and target == RENDER_TARGET and "error" not in p:
                    keep = os.path.join(work, "render-peer")
                    for ext in (".1.node", ".1.ele"):
                        shutil.copy(os.path.join(work, best["stem"] + ext), keep + ext)
                    render = (out, keep + ".1.ele", src)
                _clean(work)
                if target == SWEEP_TARGET:
                    row["variants"] = []
                    for ratio, flags in VARIANTS:
                        v, _ = _peer_row(bench, build, src, target, diag, work, [], s, ratio, flags,
                                         start=p.get("alpha_rel", 1 / 12.0) * diag)
                        row["variants"].append(v)
                        _clean(work)
            row["peer"] = p
            rows.append(row)
            if not (name == RENDER_MODEL and target == RENDER_TARGET) and os.path.exists(out):
                os.remove(out)
    picture = None
    if render and shutil.which("xvfb-run"):
        png = os.path.join(bench.RESULTS, "frontier.png")
        r = bench.run(["xvfb-run", "-a", "-s", "-screen 0 1600x1600x24", "/usr/bin/python3",
                       os.path.join(bench.ROOT, "scripts", "render-frontier.py"),
                       render[0], render[1], render[2], png], timeout=TIMEOUT)
        if r.returncode == 0 and os.path.exists(png):
            picture = os.path.basename(png)
        else:
            _log("render failed: " + r.stderr.strip()[-300:])
    shutil.rmtree(work, ignore_errors=True)
    plot = os.path.join(bench.RESULTS, "frontier-plot.png")
    plot = os.path.basename(plot) if rows and _plot(rows, plot) else None
    return rows, _markdown(rows, picture, plot)


def _hausdorff(m):
    """Both distances at once: the larger of b->S (over the boundary faces'
    samples when measured, else tetstat's vertices) and S->b, in diag."""
    b = m.get("faces_dist_max_diag")
    return max(m["dist_max_diag"] if b is None else b, m["surface_dist_max_diag"])


def _plot(rows, png):
    """min dihedral against the two-sided distance, one panel per model:
    souptet and the peer at every target, the peer's other settings at
    SWEEP_TARGET. False when matplotlib is missing."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    models = []
    for r in rows:
        if r["model"] not in models:
            models.append(r["model"])
    cols = 3
    nrow = (len(models) + cols - 1) // cols
    fig, axes = plt.subplots(nrow, cols, figsize=(5 * cols, 4.2 * nrow), squeeze=False)
    marks = {"-pqY": "v", "-pq": "s", "-pq1.2/15": "D"}
    for ax, model in zip(axes.ravel(), models):
        mr = [r for r in rows if r["model"] == model]
        for who, key, style in (("souptet", "souptet", "r*-"), ("wrap+TetGen -pq, offset alpha/30",
                                                                "peer", "bo-")):
            pts = [(r["target"], r[key]) for r in mr if "tets" in r[key] and "error" not in r[key]]
            ax.plot([_hausdorff(m) for _, m in pts], [m["min_dihedral"] for _, m in pts], style,
                    ms=11 if key == "souptet" else 6, label=who)
            for t, m in pts:
                ax.annotate(str(m["tets"]), (_hausdorff(m), m["min_dihedral"]), fontsize=7,
                            xytext=(4, 3), textcoords="offset points")
        for r in mr:
            for v in r.get("variants", []):
                if "tets" not in v or "error" in v:
                    continue
                ax.plot([_hausdorff(v)], [v["min_dihedral"]], marks.get(v["tetgen"], "o"),
                        color="tab:green", mfc="none",
                        label="wrap+TetGen %s, offset alpha/%g" % (v["tetgen"], 1 / v["offset_of_alpha"]))
                ax.annotate("%d" % v["tets"], (_hausdorff(v), v["min_dihedral"]), fontsize=7,
                            xytext=(4, -9), textcoords="offset points", color="tab:green")
        ax.set_title(model)
        ax.set_xlabel("max(b->S, S->b) / box diagonal")
        ax.set_ylabel("min dihedral (deg)")
        ax.set_xlim(left=0)
        ax.set_ylim(0, 45)
        ax.grid(alpha=0.3)
    for ax in axes.ravel()[len(models):]:
        ax.axis("off")
    h, l = axes.ravel()[0].get_legend_handles_labels()
    seen = {}
    for hh, ll in zip(h, l):
        seen.setdefault(ll, hh)
    fig.legend(list(seen.values()), list(seen.keys()), loc="lower center", ncol=3, fontsize=8)
    fig.suptitle("souptet (soupmesh --tets N) beside alpha wrap + TetGen: up and left is better;"
                 " labels: tets (other settings at ~%d)" % SWEEP_TARGET, fontsize=10)
    fig.tight_layout(rect=(0, 0.07, 1, 0.96))
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return True


def _f(x, fmt):
    return "-" if x is None else fmt % x


def _markdown(rows, picture, plot=None):
    md = ["## frontier: souptet beside alpha wrap + TetGen at matched tet counts",
          "",
          "souptet: `soupmesh --tets N --threads %d --offset-best-effort` (its defaults: one"
          " try, offset 0.4 h). Peer: CGAL `alpha_wrap_3` (bench/alpha_wrap) with offset alpha/30,"
          " then `tetgen -pq` on the wrap, alpha searched (at most %d runs) for N tets within"
          " %d%%. Both measured by `tetstat --json --surface S`, S the input."
          " *b->S*: the farthest boundary vertex from S; *S->b*: the farthest point of S from"
          " the boundary; both as a fraction of S's box diagonal, and in h (souptet's lattice"
          " cell width at that target; the peer's distances divided by the same h). *b->S"
          " faces*: as b->S, but over 7 points of every boundary face (corners, centroid,"
          " centroid-corner midpoints; CGAL AABB tree, floating point), which sees a boundary"
          " triangle that bridges a concavity between vertices near S. *encl*:"
          " tetstat's exact enclosure of S (yes / no / unverified; inside: fraction of S's"
          " vertices in the mesh, cross: S triangles crossing the boundary). *s*: wall seconds"
          " (souptet: the whole soupmesh run, its size search included; peer: alpha_wrap +"
          " tetgen for the chosen alpha, the whole alpha search in brackets)." % (
              THREADS, SEARCH, int(TOLERANCE * 100)),
          "",
          "| model | N | mesher | tets | min / max dihedral | b->S diag (h) | b->S faces diag"
          " | S->b diag (h) | encl (inside, cross) | s | how |",
          "|---|---|---|---|---|---|---|---|---|---|---|"]
    wins = {"min_dihedral": 0, "max_dihedral": 0, "dist_max_diag": 0,
            "surface_dist_max_diag": 0, "seconds": 0}
    every, pairs = 0, 0
    for r in rows:
        s, p = r["souptet"], r["peer"]
        for who, m in (("souptet", s), ("alpha wrap + TetGen", p)):
            if "error" in m or "tets" not in m:
                md.append("| %s | %d | %s | fails: %s ||||||||" % (
                    r["model"], r["target"], who, m.get("error", "not run")[:100]))
                continue
            h = s.get("h")
            bh = m["dist_max"] / h if h else None
            sh = m["surface_dist_max"] / h if h else None
            tets = "%d" % m["tets"]
            if who != "souptet" and not m.get("matched"):
                tets += " (miss)"
            secs = "%.1f" % m["seconds"]
            if who != "souptet":
                secs += " (%.1f)" % m["search_seconds"]
            md.append("| %s | %d | %s | %s | %.1f / %.1f | %.3f (%s) | %s | %.3f (%s) | %s (%.4g%%, %d) | %s | %s |" % (
                r["model"], r["target"], who, tets, m["min_dihedral"], m["max_dihedral"],
                m["dist_max_diag"], _f(bh, "%.2f"), _f(m.get("faces_dist_max_diag"), "%.3f"),
                m["surface_dist_max_diag"], _f(sh, "%.2f"),
                m["enclosure"], 100.0 * m["fraction_inside"], m["crossing_triangles"], secs,
                m["how"]))
        if "error" in s or "error" in p or "tets" not in p:
            continue
        pairs += 1
        better = {"min_dihedral": s["min_dihedral"] > p["min_dihedral"],
                  "max_dihedral": s["max_dihedral"] < p["max_dihedral"],
                  "dist_max_diag": s["dist_max_diag"] < p["dist_max_diag"],
                  "surface_dist_max_diag": s["surface_dist_max_diag"] < p["surface_dist_max_diag"],
                  "seconds": s["seconds"] < p["seconds"]}
        for k, v in better.items():
            wins[k] += v
        every += all(better.values())
    if pairs:
        md += ["", "souptet better than the peer, of %d model x N pairs: min dihedral %d, max"
               " dihedral %d, b->S %d, S->b %d, time %d (peer: the chosen alpha's run only);"
               " on all five at once: %d." % (
                   pairs, wins["min_dihedral"], wins["max_dihedral"], wins["dist_max_diag"],
                   wins["surface_dist_max_diag"], wins["seconds"], every)]
        enc = [(r["model"], r["target"]) for r in rows if r["peer"].get("encloses")]
        md.append("Peer meshes tetstat finds enclosing: %d of %d; souptet's: %d of %d." % (
            len(enc), pairs, sum(1 for r in rows if r["souptet"].get("encloses")), pairs))
    wv = [r["peer"]["wrap_vertices_dist_max_diag"] for r in rows
          if "wrap_vertices_dist_max_diag" in r["peer"]]
    if wv:
        md.append("The wraps' own vertices lie %.3f-%.3f diagonals from S (`alpha_wrap distance`:"
                  " the offset); the peer's larger b->S comes from the Steiner points `tetgen -pq`"
                  " puts on the wrap's triangles where they bridge concavities. tetstat samples"
                  " b->S at boundary vertices only, for both meshers." % (min(wv), max(wv)))
    md += _variants_markdown(rows)
    if plot:
        md += ["", "![min dihedral against the two-sided distance max(b->S faces, S->b), per model:"
               " souptet and the peer at each N, the peer's other settings at ~%d](%s)" % (
                   SWEEP_TARGET, plot)]
    if picture:
        md += ["", "![souptet (left) and alpha wrap + TetGen (right) on the %s at ~%d tets,"
               " coloured by each tet's min dihedral](%s)" % (RENDER_MODEL, RENDER_TARGET, picture)]
    return "\n".join(md) + "\n"


QUALITY = (("min_dihedral", 1), ("max_dihedral", -1), ("dist_max_diag", -1),
           ("surface_dist_max_diag", -1))


def _dominates(a, b):
    """a at least as good as b on every quality axis and better on one."""
    ge = all((a[k] - b[k]) * sgn >= 0 for k, sgn in QUALITY)
    return ge and any((a[k] - b[k]) * sgn > 0 for k, sgn in QUALITY)


def _variants_markdown(rows):
    vr = [r for r in rows if r.get("variants")]
    if not vr:
        return []
    md = ["", "### The peer's other settings at ~%d tets" % SWEEP_TARGET, "",
          "Where the peer could trade distance for angles: the offset a larger fraction of alpha"
          " (a rounder wrap), TetGen keeping the wrap as the boundary (`-Y`: no Steiner point on"
          " it), or asked for dihedral angles of 15 degrees at least (`-q1.2/15`); alpha searched"
          " again for the count each time. *dominated*: souptet's mesh at least as good on all"
          " four quality axes (min and max dihedral, b->S at vertices as tetstat measures it,"
          " S->b) and better on one;"
          " *dominates*: the reverse.",
          "",
          "| model | mesher | tets | min / max dihedral | b->S diag | b->S faces | S->b diag"
          " | encl | s | how | vs souptet |",
          "|---|---|---|---|---|---|---|---|---|---|---|"]
    dom, tot, rev = 0, 0, 0
    for r in vr:
        s = r["souptet"]
        if "error" in s:
            continue
        md.append("| %s | souptet | %d | %.1f / %.1f | %.3f | %s | %.3f | %s | %.1f | %s | |" % (
            r["model"], s["tets"], s["min_dihedral"], s["max_dihedral"], s["dist_max_diag"],
            _f(s.get("faces_dist_max_diag"), "%.3f"),
            s["surface_dist_max_diag"], s["enclosure"], s["seconds"], s["how"]))
        for v in [r["peer"]] + r["variants"]:
            if "error" in v or "tets" not in v:
                md.append("| %s | alpha wrap + TetGen | fails: %s |||||||| alpha/%g; tetgen %s | |" % (
                    r["model"], v.get("error", "not run")[:80], 1 / v["offset_of_alpha"],
                    v["tetgen"]))
                continue
            tot += 1
            vs = "dominated" if _dominates(s, v) else "dominates" if _dominates(v, s) else "trade"
            dom += vs == "dominated"
            rev += vs == "dominates"
            md.append("| %s | alpha wrap + TetGen | %d%s | %.1f / %.1f | %.3f | %s | %.3f | %s | %.1f | %s | %s |" % (
                r["model"], v["tets"], "" if v["matched"] else " (miss)", v["min_dihedral"],
                v["max_dihedral"], v["dist_max_diag"], _f(v.get("faces_dist_max_diag"), "%.3f"),
                v["surface_dist_max_diag"], v["enclosure"],
                v["seconds"], v["how"], vs))
    md += ["", "souptet dominates %d of %d peer meshes at ~%d tets; %d dominate souptet's." % (
        dom, tot, SWEEP_TARGET, rev)]
    return md
