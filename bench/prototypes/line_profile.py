#!/usr/bin/env python3
"""The samples of a `perf record` of a render, by kernel function (BENCHMARKS.md, "Where the time
goes, by source line"). PoCL adds debug information to the kernels it builds when asked to
(`POCL_EXTRA_BUILD_FLAGS=-g`), so perf attributes samples to the kernel's source lines, inlined
code included; this sums them by the function (or statement macro) whose body holds the line,
found by reading the kernel sources.

    POCL_CACHE_DIR=$(mktemp -d) POCL_EXTRA_BUILD_FLAGS=-g LUCENT_CACHE_DIR=off \\
      perf record -e cpu-clock -F 4000 -o perf.data build/lucent render SCENE -o x.pfm --spp 64
    python3 bench/prototypes/line_profile.py perf.data [--kernels kernels] [--top 30]

Each row: the share of all samples, the symbol perf charged (the out-of-line function the code
was inlined into: bvh_trace, integrate, the work-group function), and kernels/FILE:FUNCTION.
Samples without a source line (spills, calls, prologues) are listed as "(no line)".
"""
import argparse
import collections
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]

# a top-level function definition starts at column 0 (clang-format) with its name before "("
FUNC = re.compile(r"^(?:static\s+|inline\s+|LC_\w+\s+|__kernel\s+|__attribute__\(\(\w+\)\)\s+)*"
                  r"[A-Za-z_][\w\s\*]*?\b([A-Za-z_]\w*)\s*\(")
MACRO = re.compile(r"^\s*#\s*define\s+([A-Za-z_]\w*)")


def spans(path):
    """(first line, last line, name) of each function body and multi-line macro of a file."""
    lines = path.read_text(errors="replace").splitlines()
    out = []
    i = 0
    while i < len(lines):
        line = lines[i]
        m = MACRO.match(line)
        if m and line.rstrip().endswith("\\"):
            j = i
            while j + 1 < len(lines) and lines[j].rstrip().endswith("\\"):
                j += 1
            out.append((i + 1, j + 1, "macro " + m.group(1)))
            i = j + 1
            continue
        m = FUNC.match(line) if line and not line[0].isspace() and not line.startswith(
            ("#", "/", "*", "typedef", "struct", "}")) else None
        if m:
            j = i
            while j < len(lines) and "{" not in lines[j] and not lines[j].rstrip().endswith(";"):
                j += 1
            if j < len(lines) and "{" in lines[j]:
                k = j
                while k < len(lines) and not (lines[k].startswith("}") or
                                              (k == j and lines[k].rstrip().endswith("}"))):
                    k += 1
                out.append((i + 1, k + 1, m.group(1)))
                i = k + 1
                continue
        i += 1
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("data")
    p.add_argument("--kernels", default=str(ROOT / "kernels"))
    p.add_argument("--top", type=int, default=30)
    a = p.parse_args()
    kernels = pathlib.Path(a.kernels)
    report = subprocess.run(["perf", "report", "-i", a.data, "--stdio", "--full-source-path",
                             "--sort", "sym,srcline", "-F", "overhead,sym,srcline"],
                            capture_output=True, text=True)
    if report.returncode != 0:
        sys.exit("line_profile: perf report failed: " + report.stderr.strip().splitlines()[-1])
    cache = {}
    by_func = collections.Counter()
    by_sym = collections.Counter()
    row = re.compile(r"^\s*([0-9.]+)%\s+\[[.k]\]\s+(\S+)\s+(.*?)\s*$")
    for line in report.stdout.splitlines():
        m = row.match(line)
        if not m:
            continue
        share, sym, src = float(m.group(1)), m.group(2), m.group(3)
        f = re.match(r"^(?:.*/)?(kernels/.+?):(\d+)$", src)
        if not f:
            if sym == "integrate" or sym == "bvh_trace" or sym.startswith("_pocl_kernel"):
                by_func[(sym, "(no line)")] += share
            else:
                by_func[("(host)", "outside the kernel")] += share
            by_sym["(host)" if sym not in ("integrate", "bvh_trace") and
                   not sym.startswith("_pocl_kernel") else sym] += share
            continue
        rel, num = f.group(1), int(f.group(2))
        by_sym[sym] += share
        if num == 0:
            by_func[(sym, rel + ": (no line)")] += share
            continue
        path = kernels.parent / rel
        if rel not in cache:
            text = path.read_text(errors="replace").splitlines() if path.exists() else []
            cache[rel] = (spans(path) if path.exists() else [], text)
        name = next((n for lo, hi, n in cache[rel][0] if lo <= num <= hi), None)
        if name is None:  # a top-level line: functions a macro defines are charged to its use
            text = cache[rel][1][num - 1].strip() if num <= len(cache[rel][1]) else ""
            name = f"line {num}: {text[:48]}"
        by_func[(sym, rel + ":" + name)] += share
    print("by symbol:")
    for sym, share in by_sym.most_common():
        print(f"  {share:6.2f}%  {sym}")
    print(f"by kernel function (top {a.top}):")
    for (sym, where), share in by_func.most_common(a.top):
        print(f"  {share:6.2f}%  {sym:<34.34}  {where}")


if __name__ == "__main__":
    main()
