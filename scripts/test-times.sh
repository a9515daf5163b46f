#!/usr/bin/env bash
# Per-test cost of the CTest suite: wall time and CPU time (user + sys of the test process and
# the processes it waited for, from wait4) of every CTest entry, run as CTest would run it (its
# command, working directory, environment and timeout), N at a time.
#
#   scripts/test-times.sh [--build DIR] [--jobs N] [--cold] [--wrap 'CMD'] [--top K] [--out FILE]
#                         [--filter REGEX]
#
#   --build DIR   build tree whose tests to run (default: build)
#   --jobs N      tests run at the same time (default: scripts/cpus.sh)
#   --cold        empty the PoCL and lucent program caches first (a fresh clone)
#   --wrap CMD    prefix for every test command, e.g. 'taskset -c 0' to emulate one core
#   --top K       print the K most expensive tests (default 20)
#   --out FILE    also write every test as TSV: name, status, wall s, cpu s
#   --filter RE   only tests whose name matches RE (Python regex)
#   --caches DIR  program caches in DIR/pocl-cache and DIR/lucent-cache (default: the build tree;
#                 scripts/test.sh runs the sanitizer stage with build/'s caches)
#
# The sanitizer build wants the environment scripts/test.sh gives it:
#   ASAN_OPTIONS=detect_leaks=0:use_sigaltstack=0 UBSAN_OPTIONS=print_stacktrace=1 \
#     scripts/test-times.sh --build build-asan --caches build
# Prints the totals and the top K by wall time and by CPU time. Needs python3 (measurement only, not the tests).
# A competing load is the caller's business, e.g.:
#   taskset -c 0 sh -c 'while :; do :; done' & scripts/test-times.sh --wrap 'taskset -c 0' --jobs 1
set -euo pipefail
cd "$(dirname "$0")/.."
build=build jobs="" cold=0 wrap="" top=20 out="" filter="" caches=""
while [[ $# -gt 0 ]]; do
  if [[ $1 != --cold && $# -lt 2 ]]; then echo "test-times: $1 needs a value" >&2; exit 2; fi
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --cold) cold=1; shift ;;
    --wrap) wrap="$2"; shift 2 ;;
    --top) top="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --filter) filter="$2"; shift 2 ;;
    --caches) caches="$2"; shift 2 ;;
    *) echo "test-times: unknown argument $1" >&2; exit 2 ;;
  esac
done
[[ -n "$jobs" ]] || jobs="$(scripts/cpus.sh)"
# (--jobs 0 started nothing and crashed in wait4; a word crashed in int())
for v in "--jobs $jobs" "--top $top"; do
  [[ ${v#* } =~ ^[1-9][0-9]*$ ]] || { echo "test-times: ${v% *} wants a positive number, got '${v#* }'" >&2; exit 2; }
done
build="$(cd "$build" && pwd)"
if [[ -n "$caches" ]]; then mkdir -p "$caches"; fi
caches="$(cd "${caches:-$build}" && pwd)"
export POCL_CACHE_DIR="$caches/pocl-cache" LUCENT_CACHE_DIR="$caches/lucent-cache"
if [[ "$cold" == 1 ]]; then rm -rf "$POCL_CACHE_DIR" "$LUCENT_CACHE_DIR"; fi
mkdir -p "$POCL_CACHE_DIR" "$LUCENT_CACHE_DIR"
echo "test-times: $build, $jobs at a time, cold=$cold, wrap='$wrap', load $(cut -d' ' -f1-3 /proc/loadavg)"
list="$(mktemp)"
trap 'rm -f "$list"' EXIT
(cd "$build" && ctest --show-only=json-v1) >"$list"
python3 - "$list" "$jobs" "$wrap" "$top" "$out" "$filter" <<'EOF'
import json, os, re, shlex, signal, subprocess, sys, time

listing, jobs, wrap, top, out, filt = sys.argv[1], int(sys.argv[2]), shlex.split(sys.argv[3]), int(sys.argv[4]), sys.argv[5], sys.argv[6]
tests = []
for t in json.load(open(listing))["tests"]:
    if filt and not re.search(filt, t["name"]):
        continue
    props = {p["name"]: p["value"] for p in t.get("properties", [])}
    env = dict(os.environ)
    for kv in props.get("ENVIRONMENT", []):
        k, _, v = kv.partition("=")
        env[k] = v
    tests.append(dict(name=t["name"], cmd=wrap + t["command"], cwd=props.get("WORKING_DIRECTORY"),
                      env=env, timeout=float(props.get("TIMEOUT", 1500))))
pending, running, done = list(tests), {}, []
t_all = time.monotonic()
while pending or running:
    while pending and len(running) < jobs:
        t = pending.pop(0)
        p = subprocess.Popen(t["cmd"], cwd=t["cwd"], env=t["env"], stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL, start_new_session=True)
        running[p.pid] = (t, p, time.monotonic())
    now = time.monotonic()
    for pid, (t, p, t0) in list(running.items()):
        if now - t0 > t["timeout"] and not t.get("killed"):
            t["killed"] = True
            os.killpg(pid, signal.SIGKILL)
    pid, status, ru = os.wait4(-1, os.WNOHANG)
    if pid == 0:
        time.sleep(0.05)
        continue
    if pid not in running:
        continue
    t, p, t0 = running.pop(pid)
    p.returncode = os.waitstatus_to_exitcode(status)
    st = "timeout" if t.get("killed") else ("ok" if p.returncode == 0 else "FAIL(%d)" % p.returncode)
    done.append((t["name"], st, time.monotonic() - t0, ru.ru_utime + ru.ru_stime))
wall_all = time.monotonic() - t_all
if out:
    with open(out, "w") as f:
        f.write("test\tstatus\twall_s\tcpu_s\n")
        for n, st, w, c in done:
            f.write("%s\t%s\t%.2f\t%.2f\n" % (n, st, w, c))
bad = [d for d in done if d[1] != "ok"]
print("tests %d, failed %d, elapsed %.1f s, sum of test wall %.1f s, sum of test cpu %.1f s"
      % (len(done), len(bad), wall_all, sum(d[2] for d in done), sum(d[3] for d in done)))
for n, st, w, c in bad:
    print("  %s: %s" % (n, st))
for key, label in ((2, "wall"), (3, "cpu")):
    print("top %d by %s time:   wall s   cpu s" % (top, label))
    for n, st, w, c in sorted(done, key=lambda d: -d[key])[:top]:
        print("  %-60s %7.2f %7.2f%s" % (n[:60], w, c, "" if st == "ok" else "  " + st))
EOF
