#!/usr/bin/env python3
"""Per-instruction profile of one function of PoCL's JIT-compiled kernel, from callgrind.

PoCL's kernel (lucent_render.so in POCL_CACHE_DIR) has no line information, so callgrind_annotate
cannot show where inside a function the instructions go. This merges a callgrind output written
with --dump-instr=yes with `objdump -d` of the kernel: every instruction with its count divided
by the number of paths (or whatever `per` is), and, with --branches, the conditional jumps taken
between 4% and 96% of the time (the candidates for mispredicted branches; BENCHMARKS.md,
"Mispredicted branches").

  POCL_MAX_PTHREAD_COUNT=1 valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file=cg.out \\
      build/lucent render SCENE -o x.pfm --spp 4 --width 96 --height 96 -q   # run it twice
  bench/prototypes/instr_profile.py cg.out bvh_trace --per 36864 [--branches]

The kernel file is the one callgrind names (it must still be in PoCL's cache).
"""
import argparse
import collections
import re
import subprocess
import sys


def counts(cg_path, fn_name):
    """Instruction address -> executions, for function fn_name of the object lucent_render.so."""
    ir = collections.Counter()
    names = {}
    cur_ob = cur_fn = so_path = None
    addr = 0
    with open(cg_path) as f:
        for line in f:
            line = line.rstrip("\n")
            m = re.match(r"^(c?ob|c?fn|c?fi|c?fl|fe)=\((\d+)\)(?: (.*))?$", line)
            if m:
                key, ident, name = m.groups()
                table = names.setdefault(key.lstrip("c")[:2], {})
                if name:
                    table[ident] = name
                if key == "ob":
                    cur_ob = table.get(ident)
                elif key == "fn":
                    cur_fn = table.get(ident)
                continue
            if line.startswith("calls="):
                next(f)  # the call's cost line: inclusive cost of the callee, not ours
                continue
            parts = line.split()
            if len(parts) < 3 or not re.match(r"^(0x[0-9a-f]+|[+-]\d+|\*)$", parts[0]):
                continue
            a = parts[0]
            if a.startswith("0x"):
                addr = int(a, 16)
            elif a[0] in "+-":
                addr += int(a)
            if cur_ob and cur_ob.endswith("lucent_render.so") and cur_fn == fn_name:
                so_path = cur_ob
                ir[addr] += int(parts[2])
    return ir, so_path


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("callgrind_out")
    ap.add_argument("function")
    ap.add_argument("--per", type=float, default=1.0, help="divide counts by this (paths)")
    ap.add_argument("--branches", action="store_true", help="list the data-dependent jumps only")
    args = ap.parse_args()
    ir, so_path = counts(args.callgrind_out, args.function)
    if not ir:
        sys.exit(f"no instructions of {args.function} in lucent_render.so in {args.callgrind_out}")
    dis = subprocess.run(["objdump", "-d", "--no-show-raw-insn", so_path], capture_output=True,
                         text=True, check=True).stdout
    rows, inside = [], False
    for line in dis.splitlines():
        head = re.match(r"^[0-9a-f]+ <(.*)>:$", line)
        if head:
            inside = head.group(1) == args.function
            continue
        m = re.match(r"^\s*([0-9a-f]+):\s*(\S+)\s*(.*)$", line)
        if inside and m:
            rows.append((ir.get(int(m.group(1), 16), 0) / args.per, m.group(1), m.group(2),
                         m.group(3)))
    if not args.branches:
        for c, a, op, rest in rows:
            print(f"{c:10.2f}  {a}: {op} {rest}")
        print(f"total {sum(r[0] for r in rows):.1f}", file=sys.stderr)
        return
    for (c, a, op, rest), nxt in zip(rows, rows[1:]):
        if op.startswith("j") and op != "jmp" and c > 0.05:
            taken = (c - min(nxt[0], c)) / c  # fall-through: at most what the next one ran
            if 0.04 < taken < 0.96:
                print(f"{c:8.2f} taken {taken:4.2f}  {a}: {op} {rest}")


if __name__ == "__main__":
    main()
