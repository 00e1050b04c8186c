"""Stage "sign": soupsign's voting speed beside the memory floor (26 plain
passes, and the same passes vectorised: bench/stream26), peak RSS beside
the grid plus one byte per voxel, on armadillo at 128 and 256 voxels.
"""
import json
import os
import re
import sys

# scripts/bench, for its helpers and settings (run, model_path, THREADS,
# REPEAT, RESULTS, ...); set by stage().
bench = None


def soupsign_run(build, field, args, out):
    """Best voting time (the tool's own -v stage timing) and the CPU seconds
    of that run's voting (all threads; says more than wall time on a shared
    machine), peak RSS and the best refinement time (None without --surface)."""
    best, best_cpu, rss, best_ref = None, None, 0, None
    for _ in range(bench.REPEAT):
        r = bench.run(["/usr/bin/time", "-f", "RSS %M", os.path.join(build, "bin", "soupsign"),
                 "-v", "--threads", str(bench.THREADS), "-o", out] + args + [field])
        if r.returncode != 0:
            raise RuntimeError("soupsign failed: " + r.stderr)
        t = float(re.search(r"signs ([0-9.]+) s", r.stderr).group(1))
        m = re.search(r"signs [0-9.]+ s \(CPU ([0-9.]+) s", r.stderr)
        cpu = float(m.group(1)) if m else None
        m = re.search(r"refinement .*, ([0-9.]+) s", r.stderr)
        if m:
            t_ref = float(m.group(1))
            best_ref = t_ref if best_ref is None else min(best_ref, t_ref)
        if best is None or t < best:
            best, best_cpu = t, cpu
        rss = max(rss, int(re.search(r"RSS (\d+)", r.stderr).group(1)))
    return best, best_cpu, rss / 1024.0, best_ref


def stream26_run(build, field, simd):
    """The floor: best wall time of bench.REPEAT runs of 26 passes and that run's
    CPU seconds (None, None if it failed)."""
    cmd = [os.path.join(build, "bench", "stream26"), field, "--threads", str(bench.THREADS),
           "--repeat", str(bench.REPEAT)] + (["--simd"] if simd else [])
    r = bench.run(cmd)
    if r.returncode != 0:
        return None, None
    j = json.loads(r.stdout)
    return j["best_s"], j.get("cpu_s")


def stage_sign(build):
    """Speed of the voting beside the memory floor (26 plain passes, and the
    same passes vectorised), peak RSS beside the grid plus one byte per voxel."""
    rows = []
    tmp = os.path.join(bench.RESULTS, "tmp")
    os.makedirs(tmp, exist_ok=True)
    for name in ("armadillo",):
        model = bench.model_path(name)
        if not model:
            continue
        for res in (128, 256):
            field = os.path.join(tmp, "%s-%d.vdb" % (name, res))
            bench.run([os.path.join(build, "bin", "soupdist"), "-r", str(res), "-o", field, model])
            out = os.path.join(tmp, "signed.vdb")
            # The baseline: reading the field and refusing it after signing it
            # once (a signed field is refused), so its peak is what the process
            # holds before voting (libraries, the grid, the reader's leftovers).
            r = bench.run([os.path.join(build, "bin", "soupsign"), "-v", "--surface", "none", "-o", out,
                     field])
            m = re.search(r"grid (\d+)x(\d+)x(\d+)", r.stderr)
            voxels = int(m.group(1)) * int(m.group(2)) * int(m.group(3)) if m else None
            r = bench.run(["/usr/bin/time", "-f", "RSS %M", os.path.join(build, "bin", "soupsign"),
                     "-q", "-o", os.path.join(tmp, "refused.vdb"), out])
            m = re.search(r"RSS (\d+)", r.stderr)
            base_mib = int(m.group(1)) / 1024.0 if m else None
            floor, floor_cpu = stream26_run(build, field, False)
            simd, simd_cpu = stream26_run(build, field, True)
            none = ["--surface", "none"]   # soupdist recorded the model: not here
            for label, args in (("default, 26 rays", none), ("default, 13 rays", none + ["--rays", "13"]),
                                ("paper", ["--rule", "paper"]),
                                ("default, --odd ignore", none + ["--odd", "ignore"]),
                                ("default, --cut off", none + ["--cut", "off"]),
                                ("default + refine", ["--surface", model])):
                t, cpu, rss, t_ref = soupsign_run(build, field, args, out)
                rows.append({"model": name, "res": res, "rule": label, "soupsign_s": t,
                             "soupsign_cpu_s": cpu, "floor_s": floor, "floor_cpu_s": floor_cpu,
                             "floor_simd_s": simd, "floor_simd_cpu_s": simd_cpu,
                             "peak_mib": rss, "before_vote_mib": base_mib, "voxels": voxels,
                             "refine_s": t_ref})
            for f in (field, out):
                if os.path.exists(f):
                    os.remove(f)
            sys.stderr.write("bench: sign %s %d done\n" % (name, res))

    def ratio(a, b):
        return "%.2f" % (a / b) if a is not None and b else "n/a"

    def num(x, fmt="%.3f"):
        return fmt % x if x is not None else "n/a"
    md = ["## soupsign: voting speed beside the memory floor",
          "",
          "Floor: `stream26`, 26 plain parallel passes over the same field, each reading every"
          " value and adding a byte vote (the least traffic 26 rays can cost); *simd*: the same"
          " passes vectorised (`stream26 --simd`). %d threads, best of %d, the same run. The"
          " paper reports 90 s at 256^3. *soupsign s* is the voting (wall), *CPU s* its CPU"
          " time over all threads in that run (the machine may be shared: CPU time is the"
          " steadier measure); *refine s* the exact near-surface refinement after it"
          " (`--surface`: BVH build included, reading the surface not). *peak MiB*: the whole"
          " process; *added MiB*: above the peak of reading the field alone (a signed field,"
          " which is refused), i.e. what the voting holds; one byte per voxel is the target." % (
              bench.THREADS, bench.REPEAT),
          "",
          "| model | N | rule | soupsign s | CPU s | floor s | floor CPU s | simd s | simd CPU s"
          " | ratio (wall) | ratio (CPU) | ratio to simd (CPU) | peak MiB | added MiB"
          " | 1 B/voxel MiB | refine s |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        ref = r.get("refine_s")
        added = r["peak_mib"] - r["before_vote_mib"] if r.get("before_vote_mib") else None
        md.append("| %s | %d | %s | %.3f | %s | %s | %s | %s | %s | %s | %s | %s | %.0f | %s | %s | %s |" % (
            r["model"], r["res"], r["rule"], r["soupsign_s"], num(r["soupsign_cpu_s"]),
            num(r["floor_s"]), num(r["floor_cpu_s"]), num(r["floor_simd_s"]),
            num(r["floor_simd_cpu_s"]), ratio(r["soupsign_s"], r["floor_s"]),
            ratio(r["soupsign_cpu_s"], r["floor_cpu_s"]),
            ratio(r["soupsign_cpu_s"], r["floor_simd_cpu_s"]), r["peak_mib"],
            num(added, "%.1f"), num(r["voxels"] / 1048576.0 if r.get("voxels") else None, "%.1f"),
            "%.3f" % ref if ref is not None else "-"))
    return rows, "\n".join(md) + "\n"


def stage(build, b):
    global bench
    bench = b
    return stage_sign(build)
