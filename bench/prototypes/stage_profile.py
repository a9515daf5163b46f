#!/usr/bin/env python3
"""Shares of a lucent render's time (perf) or instructions (callgrind) per path-tracing stage,
for a render made with the kernels of bench/prototypes/make-noinline-kernels.sh (each stage a
function of its own). BENCHMARKS.md, "Where the time goes", was made with it:

  bench/prototypes/make-noinline-kernels.sh /tmp/ni
  export LUCENT_KERNEL_DIR=/tmp/ni/kernels POCL_MAX_PTHREAD_COUNT=2
  build/lucent render SCENE -o x.pfm --spp N          # once: builds the kernel into the caches
  perf record -e cpu-clock -F 1000 -o perf.data build/lucent render SCENE -o x.pfm --spp N
  bench/prototypes/stage_profile.py perf perf.data
  valgrind --tool=callgrind --callgrind-out-file=cg.out build/lucent render SCENE -o x.pfm ...
  bench/prototypes/stage_profile.py callgrind cg.out [PATHS]   # (run it twice: the first run
                                                               # under valgrind compiles again)

perf: shares of the samples in the stage functions and the host's per-pass work; callgrind: the
inclusive instructions of each function the work-group function calls, calls and instructions
per call (per path with PATHS = width x height x spp). Under valgrind PoCL compiles for AVX2
(valgrind has no AVX-512), so instruction counts are those of the AVX2 build.
"""
import re
import subprocess
import sys

STAGES = [
    ("traversal, closest hit", ["scene_intersect", "bvh_trace"]),
    ("traversal, shadow rays (any hit)", ["scene_occluded"]),
    ("hit point, normals, uv (interaction_from_hit)",
     ["interaction_from_hit", "_cl_atan2", "Sleef_asinf_u10", "Sleef_atan2f_u10"]),
    ("BSDF: material, eval, sample", ["bsdf_sample", "bsdf_eval", "bsdf_from_material"]),
    ("light sampling and pdfs", ["light_sample", "light_pdf", "env_radiance"]),
    ("random numbers (lc_rand8, lc_rand2)", ["lc_rand8", "lc_rand2"]),
    ("camera ray and pixel filter", ["camera_generate_ray", "filter_sample", "Sleef_logf_u10"]),
    # integrate() is a function of its own in every build (LC_POCL_NOINLINE): its own samples are
    # the path loop's; PoCL names the work-group function _workgroup or _workgroup_fast
    ("rest of the kernel: path loop, MIS, frames, spawn, film write",
     ["integrate", "_pocl_kernel_lucent_render_workgroup",
      "_pocl_kernel_lucent_render_workgroup_fast"]),
    ("host, per pass: accumulation, read-back", ["lucent::render", "__memmove_avx512_unaligned_erms"]),
]


def run(cmd):
    return subprocess.run(cmd, capture_output=True, text=True, check=True).stdout


def perf(path):
    out = run(["perf", "report", "-i", path, "--sort", "sym", "--stdio"])
    share = {}
    for line in out.splitlines():
        m = re.match(r"\s*([\d.]+)%\s+\[.\]\s+(\S+)", line)
        if m:
            share[m.group(2)] = share.get(m.group(2), 0.0) + float(m.group(1))
    vals = [(name, sum(share.get(s, 0.0) for s in syms)) for name, syms in STAGES]
    total = sum(v for _, v in vals)
    for name, v in vals:
        print("  %-64s %5.1f%%" % (name, 100 * v / total))
    print("  (these: %.1f%% of the process's samples; the rest is start-up, scene load, BVH build)"
          % total)


def callgrind(path, paths=None):
    tree = run(["callgrind_annotate", "--tree=calling", "--inclusive=yes", "--threshold=100", path])
    flat = run(["callgrind_annotate", "--threshold=100", path])
    num = lambda s: int(s.replace(",", ""))
    lines = tree.splitlines()
    def callees_of(fn):
        for i, line in enumerate(lines):
            m = re.match(r"\s*([\d,]+) \([^)]*\)\s+\*\s+\S+:(\S+)", line)
            if m and m.group(2) == fn:
                out = {}
                for l2 in lines[i + 1:]:
                    m2 = re.match(r"\s*([\d,]+) \([^)]*\)\s+>\s+\S+:(\S+) \(([\d,]+)x\)", l2)
                    if not m2:
                        break
                    out[m2.group(2)] = (num(m2.group(1)), num(m2.group(3)))
                return num(m.group(1)), out
        return None, {}

    wg, callees = callees_of("_pocl_kernel_lucent_render_workgroup")
    if wg is None:
        sys.exit("stage_profile.py: no _pocl_kernel_lucent_render_workgroup in " + path)
    # integrate() is a function of its own (LC_POCL_NOINLINE): its callees are the stages.
    if "integrate" in callees:
        total, inner = callees_of("integrate")
        del callees["integrate"]
        for k, v in inner.items():
            old = callees.get(k, (0, 0))
            callees[k] = (old[0] + v[0], old[1] + v[1])
    rest = wg - sum(v[0] for v in callees.values())
    print("kernel (work-group function, inclusive): %d instructions" % wg)
    rows = sorted(callees.items(), key=lambda kv: -kv[1][0])
    rows.append(("(rest: path loop, MIS, frames, spawn, film write, work-item loop)", (rest, 0)))
    for name, (ir, calls) in rows:
        extra = "  %d calls, %.0f per call" % (calls, ir / calls) if calls else ""
        if paths:
            extra += "  %.0f per path" % (ir / paths)
        print("  %-66s %12d  %5.1f%%%s" % (name, ir, 100.0 * ir / wg, extra))
    for line in flat.splitlines():
        m = re.match(r"\s*([\d,]+) \([^)]*\)\s+(.*)", line)
        if m and ("lucent::render(" in m.group(2) or "__memcpy_avx_unaligned_erms" in m.group(2)):
            print("  host: %-60s %12d  %5.2f%% of the kernel's" % (m.group(2)[:60], num(m.group(1)),
                                                                   100.0 * num(m.group(1)) / wg))


def main():
    if len(sys.argv) < 3 or sys.argv[1] not in ("perf", "callgrind"):
        sys.exit(__doc__)
    if sys.argv[1] == "perf":
        perf(sys.argv[2])
    else:
        callgrind(sys.argv[2], float(sys.argv[3]) if len(sys.argv) > 3 else None)


if __name__ == "__main__":
    main()
