#!/usr/bin/env bash
# Prints the number of CPUs this process may really use: the smallest of the CPUs in its affinity
# mask (nproc) and the cgroup CPU quota (cgroup v2 cpu.max, or v1 cpu.cfs_quota_us /
# cpu.cfs_period_us), rounded up, at least 1. On a container whose quota is far below the host's
# CPU count, nproc alone reports the host's CPUs.
set -euo pipefail
n="$(nproc 2>/dev/null || echo 1)"
limit() {  # quota period: lower n to ceil(quota / period)
  if [[ "$1" =~ ^[0-9]+$ && "$2" =~ ^[0-9]+$ && "$1" -gt 0 && "$2" -gt 0 ]]; then
    local q=$((($1 + $2 - 1) / $2))
    if [[ "$q" -lt "$n" ]]; then n="$q"; fi
  fi
}
# cgroup v2: cpu.max of this process's cgroup and of every ancestor
v2="$(sed -n 's/^0::\(.*\)$/\1/p' /proc/self/cgroup 2>/dev/null || true)"
d="/sys/fs/cgroup${v2%/}"
while [[ "$d" == /sys/fs/cgroup* ]]; do
  if [[ -r "$d/cpu.max" ]]; then
    read -r quota period <"$d/cpu.max" || true
    limit "${quota:-}" "${period:-}"
  fi
  [[ "$d" == /sys/fs/cgroup ]] && break
  d="$(dirname "$d")"
done
# cgroup v1: cpu.cfs_quota_us / cpu.cfs_period_us of this process's cpu cgroup and its ancestors
v1="$(sed -n 's/^[0-9]*:\([^:]*,\)*cpu\(,[^:]*\)*:\(.*\)$/\3/p' /proc/self/cgroup 2>/dev/null | head -1 || true)"
for root in /sys/fs/cgroup/cpu /sys/fs/cgroup/cpu,cpuacct /sys/fs/cgroup/cpuacct,cpu; do
  [[ -d "$root" ]] || continue
  d="$root${v1%/}"
  while [[ "$d" == "$root"* ]]; do
    if [[ -r "$d/cpu.cfs_quota_us" && -r "$d/cpu.cfs_period_us" ]]; then
      limit "$(cat "$d/cpu.cfs_quota_us")" "$(cat "$d/cpu.cfs_period_us")"
    fi
    [[ "$d" == "$root" ]] && break
    d="$(dirname "$d")"
  done
  break
done
if [[ "$n" -lt 1 ]]; then n=1; fi
echo "$n"
