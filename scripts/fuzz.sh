#!/usr/bin/env bash
# Builds the fuzz targets of tests/fuzz (clang, libFuzzer, AddressSanitizer + UndefinedBehavior-
# Sanitizer) in build-fuzz/ and runs each for SECONDS (default 60):
#
#   scripts/fuzz.sh [--if-available] [SECONDS] [TARGET...]
#
# TARGET: scene, obj, texture, render_image, part (default: all five). FUZZ_JOBS=N runs N targets at
# once (default 1). The corpus of each target grows in build-fuzz/fuzz/corpus/TARGET (seeded on
# every run from scenes/ and assets/ by lucent_fuzz_seeds); crashes, leaks and UB reports land in
# build-fuzz/fuzz/artifacts/TARGET/ and make the script fail. --if-available exits 0 with a
# message when clang with libFuzzer is missing (CI); without it that is an error.
# Needs the Debian packages clang and libclang-rt-14-dev (scripts/install-deps.sh --with-fuzz);
# FUZZ_CC and FUZZ_CXX name other compilers (default clang, clang++); FUZZ_FLAGS the optimisation
# and debug flags (default "-O1 -g1": half the build time of -O2 -g, for CI's smoke run; long
# campaigns may prefer -O2); FUZZ_DECODER_CMP=OFF compiles the third-party decoders without
# comparison tracing (tests/fuzz/CMakeLists.txt: about 3x the executions per second of
# fuzz_render_image, whose time goes to stb_image's JPEG decoder; default ON).
set -euo pipefail
cd "$(dirname "$0")/.."

optional=0
if [[ "${1:-}" == "--if-available" ]]; then
  optional=1
  shift
fi
seconds="${1:-60}"
shift || true
targets=("$@")
if [[ ${#targets[@]} -eq 0 ]]; then targets=(scene obj texture render_image part); fi
jobs="${FUZZ_JOBS:-1}"
cc="${FUZZ_CC:-clang}"
cxx="${FUZZ_CXX:-clang++}"

# clang with libFuzzer: compile and link a trivial target
probe_dir="$(mktemp -d)"
trap 'rm -rf "$probe_dir"' EXIT
echo 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }' \
  >"$probe_dir/probe.cpp"
if ! command -v "$cxx" >/dev/null ||
  ! "$cxx" -fsanitize=fuzzer,address,undefined "$probe_dir/probe.cpp" -o "$probe_dir/probe" \
    >/dev/null 2>&1; then
  msg="fuzz: $cxx with libFuzzer not found (Debian packages clang and libclang-rt-14-dev)"
  if [[ $optional -eq 1 ]]; then
    echo "$msg: fuzzing skipped"
    exit 0
  fi
  echo "$msg" >&2
  exit 1
fi

flags="${FUZZ_FLAGS:--O1 -g1} -DNDEBUG"
cmake -S . -B build-fuzz $(scripts/generator.sh build-fuzz) -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLUCENT_FUZZ=ON -DLUCENT_BUILD_TESTS=OFF \
  -DLUCENT_BUILD_BENCH=OFF -DLUCENT_FUZZ_DECODER_CMP="${FUZZ_DECODER_CMP:-ON}" \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$flags" \
  "-DCMAKE_C_FLAGS_RELWITHDEBINFO=$flags" >/dev/null
cmake --build build-fuzz --target lucent_fuzz_all -j"$(nproc)"

work="$PWD/build-fuzz/fuzz"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$PWD/tests/fuzz/ubsan.supp"
export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=0"
rm -rf "$work/seeds"
build-fuzz/tests/fuzz/lucent_fuzz_seeds . "$work/seeds"

run_one() {
  local t="$1"
  local dict max_len
  case "$t" in
    scene) dict=scene.dict max_len=16384 ;;
    obj) dict=obj.dict max_len=16384 ;;
    texture | render_image) dict=image.dict max_len=16384 ;;
    part) dict=part.dict max_len=16384 ;;
    *) echo "fuzz: unknown target '$t' (scene, obj, texture, render_image, part)" >&2; return 2 ;;
  esac
  mkdir -p "$work/corpus/$t" "$work/artifacts/$t"
  # each target in its own directory: libFuzzer writes crash files to the working directory
  # when no artifact prefix applies
  (cd "$work/artifacts/$t" &&
    "$OLDPWD/build-fuzz/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -max_len="$max_len" \
      -rss_limit_mb=2560 -timeout=30 -dict="$OLDPWD/tests/fuzz/$dict" -print_final_stats=1 \
      -artifact_prefix="$work/artifacts/$t/" "$work/corpus/$t" "$work/seeds/$t" \
      >"$work/$t.log" 2>&1)
}

summary() {
  local t="$1" rc="$2"
  local log="$work/$t.log" runs rate cov ft
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*$' || true)
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*$' || true)
  printf 'fuzz: %-13s %10s runs %7s exec/s  cov %6s  ft %6s  %s\n' "$t" "${runs:-?}" \
    "${rate:-?}" "${cov:-?}" "${ft:-?}" "$([[ $rc -eq 0 ]] && echo ok || echo "FAILED (see $log)")"
}

failed=0
pids=()
names=()
for t in "${targets[@]}"; do
  run_one "$t" &
  pids+=($!)
  names+=("$t")
  if [[ ${#pids[@]} -ge $jobs ]]; then
    rc=0
    wait "${pids[0]}" || rc=$?
    summary "${names[0]}" "$rc"
    [[ $rc -eq 0 ]] || failed=1
    pids=("${pids[@]:1}")
    names=("${names[@]:1}")
  fi
done
for i in "${!pids[@]}"; do
  rc=0
  wait "${pids[$i]}" || rc=$?
  summary "${names[$i]}" "$rc"
  [[ $rc -eq 0 ]] || failed=1
done
if [[ $failed -ne 0 ]]; then
  echo "fuzz: failures; the inputs are in $work/artifacts/ (replay: build-fuzz/tests/fuzz/fuzz_TARGET FILE)" >&2
  exit 1
fi
