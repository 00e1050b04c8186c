"""Stage "corpus": the damaged corpus: scripts/fetch-corpus, then
scripts/damage-corpus (MeshLab, verified with soupinfo); the soupinfo
counts of every model and damage, and how long the preparation took
(outputs already made are cached, so a second run only verifies).
"""
import json
import os
import re
import sys
import time

# scripts/bench, for its helpers and settings (run, model_path, THREADS,
# REPEAT, RESULTS, ...); set by stage().
bench = None


def stage_corpus(build):
    """The damaged corpus: scripts/fetch-corpus, then scripts/damage-corpus
    (MeshLab, verified with soupinfo); the soupinfo counts of every model and
    damage, and how long the preparation took (outputs already made are
    cached, so a second run only verifies)."""
    names = bench.run([os.path.join(bench.ROOT, "scripts", "damage-corpus"), "--list"]).stdout.split()
    t0 = time.time()
    fetch = bench.run([os.path.join(bench.ROOT, "scripts", "fetch-corpus")] + names)
    t_fetch = time.time() - t0
    t0 = time.time()
    dmg = bench.run([os.path.join(bench.ROOT, "scripts", "damage-corpus"),
               "--soupinfo", os.path.join(build, "bin", "soupinfo")])
    t_damage = time.time() - t0
    sys.stderr.write(dmg.stdout + dmg.stderr)
    if dmg.returncode != 0:
        raise RuntimeError("damage-corpus failed:\n" + dmg.stderr)
    m = re.search(r"(\d+) MeshLab runs now \(([0-9.]+) s of MeshLab\), (\d+) cached", dmg.stdout)
    made, meshlab_s, cached = (int(m.group(1)), float(m.group(2)), int(m.group(3))) if m else (0, 0.0, 0)
    skipped = [l for l in dmg.stdout.splitlines() if l.startswith("skipped")]
    with open(os.path.join(bench.DAMAGED, "manifest.json")) as f:
        man = json.load(f)
    rows = [dict(model=e["model"], damage="(clean)", **e["counts"]) for e in man["models"]]
    rows += [dict(model=e["model"], damage=e["damage"], **e["counts"]) for e in man["damaged"]]
    order = {e["model"]: i for i, e in enumerate(man["models"])}
    rows.sort(key=lambda r: (order[r["model"]], -1 if r["damage"] == "(clean)"
                             else man["damages"].index(r["damage"])))
    md = ["## Damaged corpus (MeshLab %s, scripts/meshlab/*.mlx)" % man["meshlab"],
          "",
          "Preparation: fetch-corpus %.1f s%s, damage-corpus %.1f s (%d MeshLab runs now, %.1f s of"
          " MeshLab, 2 at a time; %d outputs cached and only verified). Every output is checked"
          " with `soupinfo --json` against what its damage must do; counts after exact welding."
          " *bnd* boundary edges, *nm* non-manifold edges, *inc* inconsistently oriented edges,"
          " *dup* duplicated triangles." % (
              t_fetch, "" if fetch.returncode == 0 else " (exit %d)" % fetch.returncode,
              t_damage, made, meshlab_s, cached),
          ""] + ["%s" % l for l in skipped] + ([""] if skipped else []) + [
          "| model | damage | V | F | welded V | pieces | bnd | holes | nm | inc | dup | closed | genus |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        md.append("| %s | %s | %d | %d | %d | %d | %d | %d | %d | %d | %d | %s | %s |" % (
            r["model"], r["damage"], r["vertices"], r["triangles"], r["welded_vertices"],
            r["pieces"], r["boundary_edges"], r["holes"], r["nonmanifold_edges"],
            r["inconsistent_edges"], r["duplicated_triangles"], "yes" if r["closed"] else "no",
            r["genus"] if r["closed_pieces"] else "-"))
    rows.append({"fetch_s": t_fetch, "damage_s": t_damage, "meshlab_runs": made,
                 "meshlab_s": meshlab_s, "cached": cached})
    return rows, "\n".join(md) + "\n"


def stage(build, b):
    global bench
    bench = b
    return stage_corpus(build)
