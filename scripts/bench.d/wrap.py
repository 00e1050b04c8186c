"""Bench stage 'wrap': soupwrap's repaired surfaces on the damaged corpus,
beside CGAL's alpha_wrap_3, and TetGen on both the raw and the repaired
surfaces.

Per model and damage (the clean model too): whether the output is closed,
2-manifold, consistently oriented and self-intersection-free (soupinfo
--json, exact), its faces, the distances both ways (output vertices to the
input, input vertices to the output; max and mean, in voxels of the
soupwrap grid: the longest side of the box / 128), and the time. CGAL's
alpha_wrap_3 runs on the same input with alpha = 2 voxels and offset =
1/2 voxel (its surface lies `offset` outside the input, ours on it; the
ball of radius alpha must not slip through the 50%-deleted models' holes).
`tetgen -pq` runs on the raw input and on soupwrap's output of the
deleted50 and soup variants. Every soupwrap output is also checked by CGAL
(`alpha_wrap check`: a polygon mesh, closed, no degenerate face, no
self-intersection, outward, by CGAL's exact predicates), independently of
soupinfo. The CAD parts are in since issue 37 (soupwrap failed on a screw
with large holes: "degenerate triangles"), their largeholes too; and
soupwrap with CGAL's check runs on every damaged input of the corpus
(manifest.json: every model and damage, symholes included), the peers on
MODELS only; a table counts the outputs that pass, per damage.
SOUPTET_BENCH_PEERS=0: soupwrap and its checks alone.

Needs the damaged corpus (make bench STAGE=corpus, or scripts/damage-corpus)
and $(BUILD)/bench/alpha_wrap (bench/alpha_wrap.cpp; CGAL from
libcgal-dev). Runs in some minutes on 2 cores: ten small models.
"""
import json
import os
import re
import shutil
import subprocess
import time

MODELS = ("bunny", "elephant", "fandisk", "torus", "man", "anchor", "pinion", "rotor",
          "joint", "couplingdown")
DAMAGES = ("deleted50", "holes", "soup", "flipped", "interpenetrating",
           "onesided", "noise", "duplicated", "largeholes")
CELLS = 128
TETGEN_DAMAGES = ("deleted50", "soup")
TETGEN_TIMEOUT = 120
PEERS = os.environ.get("SOUPTET_BENCH_PEERS", "1") != "0"


def _inputs(bench):
    """[(model, damage, path, peers?)]: MODELS clean and damaged (peers
    run), then every other damaged input of the manifest (soupwrap only)."""
    out = []
    for m in MODELS:
        clean = bench.model_path(m)
        if clean:
            out.append((m, "(clean)", clean, PEERS))
        out += [(m, d, os.path.join(bench.DAMAGED, "%s-%s.off" % (m, d)), PEERS) for d in DAMAGES]
    try:
        with open(os.path.join(bench.DAMAGED, "manifest.json")) as f:
            man = json.load(f)
    except (OSError, ValueError):
        return out
    seen = {(m, d) for m, d, _, _ in out}
    out += [(e["model"], e["damage"], os.path.join(bench.DAMAGED, e["file"]), False)
            for e in man["damaged"] if (e["model"], e["damage"]) not in seen]
    return out


def _info(bench, build, path, self_check=True):
    r = bench.run([os.path.join(build, "bin", "soupinfo"), "--json"] +
                  ([] if self_check else ["--no-self-check"]) + [path])
    if r.returncode != 0:
        return None
    i = json.loads(r.stdout)[0]
    return {"closed": i["closed"] and i["boundary_edges"] == 0 and i["nonmanifold_edges"] == 0,
            "manifold": i["closed"] and i["nonmanifold_vertices"] == 0,
            "oriented": i["inconsistent_edges"] == 0 and i["nonorientable_pieces"] == 0,
            "self_free": i["self_intersecting_pairs"] == 0,  # None: unchecked
            "degenerate": i["degenerate_triangles"] + i["collinear_triangles"],
            "pieces": i["pieces"], "faces": i["triangles"],
            "voxel": max(h - l for h, l in zip(i["hi"], i["lo"])) / CELLS}


def _dist(bench, peer, a, b, voxel):
    r = bench.run([peer, "distance", a, b])
    if r.returncode != 0:
        return None
    d = json.loads(r.stdout)
    return {"max": d["max"] / voxel, "mean": d["mean"] / voxel}


def _tetgen(bench, src, tmp):
    """tetgen -pq on a copy of src: 'N tets', or what went wrong."""
    if not shutil.which("tetgen"):
        return "n/a"
    dst = os.path.join(tmp, "tg-" + os.path.basename(src))
    shutil.copy(src, dst)
    base = dst[:dst.rfind(".")]
    try:
        r = bench.run(["tetgen", "-pq", dst], timeout=TETGEN_TIMEOUT)
        out = r.stdout + r.stderr
        m = re.search(r"Mesh tetrahedra: (\d+)", out)
        if r.returncode != 0:
            err = [l for l in out.splitlines() if "rror" in l or "ntersect" in l]
            res = "fails (%s%s)" % ("exit %d" % r.returncode if r.returncode > 0
                                     else "signal %d" % -r.returncode,
                                     ": " + err[0].strip()[:50] if err else "")
        elif m and int(m.group(1)) > 0 and os.path.exists(base + ".1.ele"):
            res = "%s tets" % m.group(1)
        else:
            res = "0 tets (open: every tet is exterior)"
    except subprocess.TimeoutExpired:
        res = "timeout %ds" % TETGEN_TIMEOUT
    for ext in (".1.ele", ".1.node", ".1.face", ".1.edge", ".1.smesh"):
        if os.path.exists(base + ext):
            os.remove(base + ext)
    os.remove(dst)
    return res


def check_table(rows):
    """Per damage: the soupwrap outputs that CGAL's exact check passes
    (closed, no degenerate face, no self-intersection, outward) of the
    inputs, and the ones that fail or that soupwrap refused."""
    md = ["", "### soupwrap --surface on every damaged input: CGAL's exact check", "",
          "`soupwrap -q --surface IN -r %d`, then `alpha_wrap check OUT` (CGAL: a closed"
          " polygon mesh, no degenerate face, no self-intersection, outward); *refused*:"
          " soupwrap exited non-zero (its own check failed); *unchecked*: the check printed"
          " no verdict (an alpha_wrap built before its check mode: `make -B"
          " BUILD/bench/alpha_wrap`)." % CELLS, "",
          "| damage | pass / inputs | refused | check fails | unchecked |", "|---|--:|---|---|--:|"]
    dmgs = []
    for r in rows:
        if r["damage"] != "(clean)" and r["damage"] not in dmgs:
            dmgs.append(r["damage"])
    tot = [0, 0]
    for d in dmgs:
        sub = [r for r in rows if r["damage"] == d]
        ok = [r for r in sub if r.get("soupwrap_cgal")]
        ref = [r["model"] for r in sub if "soupwrap_error" in r]
        bad = [r["model"] for r in sub if "soupwrap" in r and r.get("soupwrap_cgal") is False]
        unk = [r for r in sub if "soupwrap" in r and r.get("soupwrap_cgal") is None]
        tot[0] += len(ok)
        tot[1] += len(sub)
        md.append("| %s | %d / %d | %s | %s | %d |" % (d, len(ok), len(sub), ", ".join(ref) or "-",
                                                       ", ".join(bad) or "-", len(unk)))
    md.append("| all damaged | %d / %d | | | |" % tuple(tot))
    return md


def stage(build, bench):
    root = bench.ROOT
    damaged = bench.DAMAGED
    tmp = os.path.join(bench.RESULTS, "tmp", "wrap")
    os.makedirs(tmp, exist_ok=True)
    peer = os.path.join(build, "bench", "alpha_wrap")
    have_peer = os.path.exists(peer)
    rows = []
    for m, dmg, src, peers in _inputs(bench):
        if not src or not os.path.exists(src):
            continue
        row = {"model": m, "damage": dmg}
        raw = _info(bench, build, src, self_check=False)
        voxel = raw["voxel"]
        out = os.path.join(tmp, "%s-%s-wrap.off" % (m, dmg))
        t0 = time.time()
        r = bench.run([os.path.join(build, "bin", "soupwrap"), "-q", "--surface", src,
                       "-r", str(CELLS), "-o", out])
        row["soupwrap_s"] = time.time() - t0
        if r.returncode != 0:
            row["soupwrap_error"] = r.stderr.strip()[-200:]
        else:
            row["soupwrap"] = _info(bench, build, out)
            if have_peer:
                rc = bench.run([peer, "check", out])
                row["soupwrap_cgal"] = (json.loads(rc.stdout)["ok"]
                                        if rc.stdout.strip() else None)
                row["soupwrap_to_input"] = _dist(bench, peer, out, src, voxel)
                row["input_to_soupwrap"] = _dist(bench, peer, src, out, voxel)
        if have_peer and peers:
            cg = os.path.join(tmp, "%s-%s-cgal.off" % (m, dmg))
            r = bench.run([peer, "wrap", src, cg, repr(2 * voxel), repr(voxel / 2)])
            if r.returncode == 0:
                o = json.loads(r.stdout)
                row["cgal_s"] = o["seconds"]
                row["cgal"] = _info(bench, build, cg)
                row["cgal_to_input"] = _dist(bench, peer, cg, src, voxel)
                row["input_to_cgal"] = _dist(bench, peer, src, cg, voxel)
            else:
                row["cgal_error"] = r.stderr.strip()[-200:]
            if os.path.exists(cg):
                os.remove(cg)
        if dmg in TETGEN_DAMAGES and peers:
            row["tetgen_raw"] = _tetgen(bench, src, tmp)
            row["tetgen_wrap"] = _tetgen(bench, out, tmp) if os.path.exists(out) else "n/a"
        if os.path.exists(out):
            os.remove(out)
        rows.append(row)
        bench.sys.stderr.write("bench: wrap %s %s done\n" % (m, dmg))

    def yn(i):
        if not i:
            return "-"
        return "".join(c for c, k in (("C", "closed"), ("M", "manifold"), ("O", "oriented"),
                                      ("S", "self_free")) if i[k]) + (
            "" if not i["degenerate"] else " %d deg" % i["degenerate"])

    def dd(d):
        return "%.2f / %.2f" % (d["max"], d["mean"]) if d else "-"

    md = ["## soupwrap: the repaired surface, beside CGAL alpha_wrap_3",
          "",
          "`soupwrap --surface IN -r %d` (soupdist + soupsign defaults in-process). Checks by"
          " `soupinfo --json` (exact): C closed, M 2-manifold (single fan at every vertex),"
          " O consistently oriented, S no self-intersecting pair. Distances max / mean in"
          " voxels (longest side / %d), out->in: output vertices to the input triangles,"
          " in->out: input vertices to the output. CGAL: `alpha_wrap_3`, alpha 2 voxels,"
          " offset 0.5 voxel (its surface lies offset outside the input by construction)."
          " Times are wall seconds: soupwrap's whole run (read, distance, signs, wrap, check,"
          " write), CGAL's wrap call only." % (CELLS, CELLS),
          "",
          "| model | damage | soupwrap | CGAL's check | faces | out->in | in->out | s | CGAL | faces | out->in | in->out | s |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        sw, cg = r.get("soupwrap"), r.get("cgal")
        cc = r.get("soupwrap_cgal")
        md.append("| %s | %s | %s | %s | %s | %s | %s | %.2f | %s | %s | %s | %s | %s |" % (
            r["model"], r["damage"], yn(sw) if sw else "error",
            "-" if cc is None else ("ok" if cc else "FAILS"), sw["faces"] if sw else "-",
            dd(r.get("soupwrap_to_input")), dd(r.get("input_to_soupwrap")), r["soupwrap_s"],
            yn(cg) if cg else ("error" if "cgal_error" in r else "n/a"), cg["faces"] if cg else "-",
            dd(r.get("cgal_to_input")), dd(r.get("input_to_cgal")),
            "%.2f" % r["cgal_s"] if "cgal_s" in r else "-"))
    ok = [r for r in rows if r.get("soupwrap") and all(r["soupwrap"][k] for k in
                                                       ("closed", "manifold", "oriented", "self_free"))
          and not r["soupwrap"]["degenerate"]]
    md += ["", "soupwrap: %d of %d inputs give a closed, 2-manifold, oriented, self-intersection-free"
           " surface without degenerate triangles." % (len(ok), len(rows))]
    cg_rows = [r for r in rows if r.get("soupwrap_cgal") is not None]
    if cg_rows:
        md.append("CGAL's exact check (closed, no degenerate face, no self-intersection, outward)"
                  " holds on %d of %d soupwrap outputs." % (
                      sum(1 for r in cg_rows if r["soupwrap_cgal"]), len(cg_rows)))
    md += check_table(rows)
    closed = [r for r in rows if r["damage"] == "(clean)" and r.get("input_to_soupwrap")]
    if closed:
        md.append("On the clean (closed) models: out->in max %.2f voxels (mean %.3f), in->out max %.2f"
                  " (mean %.3f); targets 1 and 1.5." % (
                      max(r["soupwrap_to_input"]["max"] for r in closed),
                      max(r["soupwrap_to_input"]["mean"] for r in closed),
                      max(r["input_to_soupwrap"]["max"] for r in closed),
                      max(r["input_to_soupwrap"]["mean"] for r in closed)))
    tg = [r for r in rows if "tetgen_raw" in r]
    if tg:
        md += ["", "### TetGen (`tetgen -pq`) on the raw input and on soupwrap's output", "",
               "| model | damage | raw input | soupwrap output |", "|---|---|---|---|"]
        for r in tg:
            md.append("| %s | %s | %s | %s |" % (r["model"], r["damage"], r["tetgen_raw"], r["tetgen_wrap"]))
    return rows, "\n".join(md) + "\n"
