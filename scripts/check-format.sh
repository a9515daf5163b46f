#!/usr/bin/env bash
# Checks that the project's C, C++ and OpenCL sources are formatted as .clang-format says, with
# clang-format 14 (Debian 12's package clang-format; other versions format some constructs
# differently, so they are not asked):
#
#   scripts/check-format.sh          # lists the files that differ and fails (a CTest entry)
#   scripts/check-format.sh --fix    # formats them in place
#
# CLANG_FORMAT names another binary. Exits 77 (a CTest skip) when no clang-format 14 is found.
# A region that must keep its hand layout is fenced by "// clang-format off" and "on" lines.
set -euo pipefail
cd "$(dirname "$0")/.."
fmt="${CLANG_FORMAT:-clang-format}"
if ! command -v "$fmt" >/dev/null; then
  echo "check-format: $fmt not found (Debian package clang-format): skipped"
  exit 77
fi
version="$("$fmt" --version)"
if [[ "$version" != *"version 14."* ]]; then
  echo "check-format: sources are formatted with clang-format 14, and $fmt is '$version': skipped"
  exit 77
fi
mapfile -t files < <(find src include kernels tests python bench -type f \
  \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' -o -name '*.cl' -o -name '*.c' \) | sort)
if [[ "${1:-}" == "--fix" ]]; then
  "$fmt" -i "${files[@]}"
  exit 0
fi
# one process for all files (a process each costs seconds); its reports name file:line:column
mapfile -t bad < <("$fmt" --dry-run "${files[@]}" 2>&1 | grep -o '^[^:]*:[0-9]*:[0-9]*: warning' |
  cut -d: -f1 | sort -u)
if [[ ${#bad[@]} -gt 0 ]]; then
  for f in "${bad[@]}"; do echo "check-format: $f: not formatted (clang-format --dry-run $f)"; done
  echo "check-format: ${#bad[@]} of ${#files[@]} files; scripts/check-format.sh --fix formats them" >&2
  exit 1
fi
echo "check-format: ${#files[@]} files formatted"
