# Sourced by the benchmark scripts (bench-scenes.sh, bench-converge.sh, bench-time-to-error.sh).
# missing_assets SCENE: the files the scene names ("file", "texture") that are absent, resolved as
# lucent resolves them: relative to the scene's directory (../shared beside this checkout, whatever
# /work/shared holds), one per line.
missing_assets() {
  local dir f
  dir=$(dirname "$1")
  { grep -o '"\(file\|texture\)": *"[^"]*"' "$1" || true; } | sed 's/.*: *"\(.*\)"$/\1/' | while read -r f; do
    [[ $f == /* ]] || f=$(realpath -m "$dir/$f")
    [[ -e $f ]] || echo "$f"
  done
}
