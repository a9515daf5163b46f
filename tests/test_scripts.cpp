// The benchmark and tool scripts (scripts/, bench/prototypes/): bad arguments get a usage or
// one-line message and a non-zero exit before anything runs, and scenes whose assets are absent
// are skipped with a message instead of stopping a benchmark. No script here renders: the build
// directories they are given hold a stand-in `lucent` that fails if it is ever called, and a
// copy of a script in a scratch "checkout" sees only the scenes written there.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "support.hpp"

namespace test_scripts {

namespace fs = std::filesystem;

namespace {

std::string q(const std::string& s) { return "'" + s + "'"; }

struct ScriptRun {
  int status = -1;
  std::string out, err;
};

// `cmd` run by the shell in `dir`, stdin empty, stdout and stderr kept
ScriptRun run(const std::string& dir, const std::string& cmd) {
  const std::string out = dir + "/run.out", err = dir + "/run.err";
  const std::string full =
      "cd " + q(dir) + " && { " + cmd + "; } </dev/null >" + q(out) + " 2>" + q(err);
  int raw = std::system(full.c_str());
  ScriptRun r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128;
  r.out = lucent::test::read_file(out);
  r.err = lucent::test::read_file(err);
  return r;
}

void make_executable(const std::string& path, const std::string& text) {
  lucent::test::write_file(path, text);
  ::chmod(path.c_str(), 0755);
}

// A build directory whose lucent must not be called (it would mean a scene was not skipped).
std::string fake_build(const std::string& dir) {
  const std::string build = dir + "/fake build";
  fs::create_directories(build);
  make_executable(build + "/lucent",
                  "#!/bin/sh\necho \"lucent: error: the stand-in lucent was called: $*\" >&2\n"
                  "exit 1\n");
  return build;
}

// A scratch checkout (a path with a space) holding copies of the given scripts and one scene
// whose mesh is absent; its ../shared is absent too.
std::string scratch_checkout(const std::string& dir, std::initializer_list<const char*> scripts) {
  const std::string root = dir + "/check out";
  fs::create_directories(root + "/scripts");
  fs::create_directories(root + "/scenes");
  for (const char* s : scripts)
    fs::copy_file(lucent::test::source_path(std::string("scripts/") + s), root + "/scripts/" + s);
  // sourced by the benchmark scripts
  fs::copy_file(lucent::test::source_path("scripts/missing-assets.sh"),
                root + "/scripts/missing-assets.sh");
  lucent::test::write_file(root + "/scenes/needs-mesh.json", R"({
  "film": {"width": 8, "height": 8},
  "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
  "shapes": [{"type": "mesh", "file": "../../absent-assets/mesh.obj", "material": "m"}],
  "lights": [{"type": "point", "position": [0, 2, 0], "intensity": [1, 1, 1]}]})");
  return root;
}

}  // namespace

// bench-scenes and bench-converge skipped a scene only when /work/shared and ../shared were both
// absent: a checkout elsewhere (a worktree) whose scenes name ../../shared/... stopped the whole
// benchmark at the first such scene ("cornell-box failed: cannot open OBJ file"), and a mesh
// outside ../shared was never skipped. Now the files the scene names are looked for where lucent
// looks: relative to the scene.
TEST(BenchScripts, ScenesWhoseMeshIsAbsentAreSkipped) {
  const std::string dir = lucent::test::temp_dir();
  const std::string build = fake_build(dir);
  const std::string root = scratch_checkout(dir, {"bench-scenes.sh", "bench-converge.sh"});

  ScriptRun r = run(root, "bash scripts/bench-scenes.sh " + q(build) + " 1 1");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("| needs-mesh | | | (skipped: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("absent-assets/mesh.obj is absent)"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("stand-in"), std::string::npos) << r.err;

  r = run(root, "bash scripts/bench-converge.sh " + q(build) + " 1e-2 8 5");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("| needs-mesh | (skipped: "), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("stand-in"), std::string::npos) << r.err;
}

// bench-time-to-error skipped only a scene file that was absent: the Cornell box without its
// ../shared mesh stopped the run there (the scenes after it never ran) and left a partial
// cornell-box.md with a table header and no rows.
TEST(BenchScripts, TimeToErrorSkipsScenesWhoseMeshIsAbsent) {
  const std::string dir = lucent::test::temp_dir();
  const std::string build = fake_build(dir);
  const std::string root = scratch_checkout(dir, {"bench-time-to-error.sh", "bench-sampling.sh"});
  fs::copy_file(lucent::test::source_path("scenes/cornell-box.json"),
                root + "/scenes/cornell-box.json");
  ScriptRun r = run(dir, "bash " + q(root + "/scripts/bench-time-to-error.sh") + " " + q(build) +
                             " 'out dir' cornell-box");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("== cornell-box: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("CornellBox-Original.obj absent, skipped"), std::string::npos) << r.out;
  // OUT_DIR is relative to the caller's directory, not the checkout's
  EXPECT_TRUE(fs::is_directory(dir + "/out dir"));
  EXPECT_FALSE(fs::exists(dir + "/out dir/cornell-box.md"));
  EXPECT_FALSE(fs::exists(root + "/out dir"));
}

// Missing or meaningless arguments: a usage or a message naming the argument, exit 2, before
// anything runs (bench-sampling and bench-time-to-error said "$1: unbound variable"; RUNS 0
// printed a table of empty cells; bench-mitsuba's SPP 1 divided by SPP - 1).
TEST(BenchScripts, BadArgumentsAreRefusedWithAMessage) {
  const std::string dir = lucent::test::temp_dir();
  const std::string build = fake_build(dir);
  const std::string s = q(lucent::test::source_path("scripts")) + "/";
  struct Case {
    std::string cmd, message;
    int status = 2;
  } cases[] = {
      {s + "bench-sampling.sh", "usage: scripts/bench-sampling.sh BUILD_DIR REF_SPP LADDER"},
      {s + "bench-sampling.sh " + q(dir) + " 64 1,2 x.json", "lucent not found", 1},
      {s + "bench-time-to-error.sh", "usage: scripts/bench-time-to-error.sh BUILD_DIR"},
      {s + "bench-scenes.sh " + q(build) + " 4 0", "RUNS must be a positive number, got '0'"},
      {s + "bench-scenes.sh " + q(build) + " x", "SPP must be a positive number, got 'x'"},
      {s + "bench-converge.sh " + q(build) + " abc", "TARGET must be a positive number"},
      {s + "bench-mitsuba.sh " + q(build) + " 1", "SPP must be a whole number of at least 2"},
      {s + "test-times.sh --jobs 0", "--jobs wants a positive number, got '0'"},
      {s + "test-times.sh --filter", "--filter needs a value"},
  };
  for (const Case& c : cases) {
    ScriptRun r = run(dir, "bash " + c.cmd);
    EXPECT_EQ(r.status, c.status) << c.cmd << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.cmd << "\n" << r.err;
    EXPECT_EQ(r.err.find("unbound variable"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("Traceback"), std::string::npos) << r.err;
  }
}

// planted-bugs.sh checked a bug's name only when its turn came: "planted-bugs.sh 1 8" ran bug
// 1's whole suite (minutes) before failing on 8, and an unknown name left its scratch copy of
// kernels/ behind.
TEST(BenchScripts, PlantedBugsChecksEveryNameFirst) {
  const std::string dir = lucent::test::temp_dir();
  ScriptRun r = run(dir, "bash " + q(lucent::test::source_path("scripts/planted-bugs.sh")) +
                             " --work " + q(dir + "/work") + " 9 baseline");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("planted-bugs: unknown bug 9"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/work"));
}

// precision-scenes.py read sys.argv by hand: "--help" became an output directory named --help
// (and no arguments a Python traceback).
TEST(BenchScripts, PythonScriptsHaveAUsage) {
  const std::string dir = lucent::test::temp_dir();
  for (const char* script : {"precision-scenes.py", "make-assets.py"}) {
    ScriptRun r =
        run(dir, "python3 " + q(lucent::test::source_path(std::string("scripts/") + script)) +
                     " --help");
    EXPECT_EQ(r.status, 0) << script << r.err;
    EXPECT_NE(r.out.find("usage: scripts/"), std::string::npos) << script << r.out;
  }
  EXPECT_FALSE(fs::exists(dir + "/--help"));
  ScriptRun r = run(dir, "python3 " + q(lucent::test::source_path("scripts/precision-scenes.py")));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("usage: scripts/precision-scenes.py OUTDIR [WIDTH]"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("Traceback"), std::string::npos) << r.err;
}

// stage_profile.py's perf mode looked for symbols that make-noinline-kernels.sh no longer makes
// (light_pdf_area, lc_rand) and left out integrate(), a function of its own in every build: the
// random numbers and the path loop read 0% and their samples were dropped from the total.
// Here a stand-in perf prints a report with the symbols of a noinline kernel.
TEST(BenchScripts, StageProfileCountsEveryNoinlineStage) {
  const std::string dir = lucent::test::temp_dir();
  make_executable(dir + "/perf", R"(#!/bin/sh
cat <<'EOF'
# Samples: 1K of event 'cpu-clock'
    40.00%  [.] scene_intersect
    10.00%  [.] integrate
    10.00%  [.] lc_rand8
     5.00%  [.] lc_rand2
     5.00%  [.] light_pdf
    10.00%  [.] light_sample
    20.00%  [.] bsdf_eval
EOF
)");
  ScriptRun r = run(dir, "PATH=" + q(dir) + ":\"$PATH\" python3 " +
                             q(lucent::test::source_path("bench/prototypes/stage_profile.py")) +
                             " perf perf.data");
  ASSERT_EQ(r.status, 0) << r.err;
  // the share printed at the end of the line that starts with `stage`
  auto share = [&](const std::string& stage) {
    size_t at = r.out.find("  " + stage);
    if (at == std::string::npos) return -1.0;
    size_t end = r.out.find("%\n", at);
    size_t begin = r.out.rfind(' ', end);
    return std::atof(r.out.substr(begin, end - begin).c_str());
  };
  EXPECT_DOUBLE_EQ(share("random numbers"), 15.0) << r.out;
  EXPECT_DOUBLE_EQ(share("light sampling and pdfs"), 15.0) << r.out;
  EXPECT_DOUBLE_EQ(share("rest of the kernel: path loop"), 10.0) << r.out;
  EXPECT_DOUBLE_EQ(share("traversal, closest hit"), 40.0) << r.out;
  EXPECT_NE(r.out.find("(these: 100.0% of the process's samples"), std::string::npos) << r.out;
}

// bench-cycles looked for the OBJ in /work/shared or ../shared, while lucent renders the scene's
// own path (../shared beside the checkout): with /work/shared present and the checkout elsewhere,
// Cycles got a mesh and lucent failed. Now the OBJ is the scene's.
TEST(BenchScripts, CyclesSkipsWhenTheScenesMeshIsAbsent) {
  const std::string dir = lucent::test::temp_dir();
  const std::string build = fake_build(dir);
  const std::string root = scratch_checkout(dir, {"bench-cycles.sh"});
  fs::copy_file(lucent::test::source_path("scenes/cornell-box.json"),
                root + "/scenes/cornell-box.json");
  make_executable(dir + "/blender",
                  "#!/bin/sh\necho 'the stand-in blender was called' >&2\n"
                  "exit 1\n");
  ScriptRun r = run(dir, "PATH=" + q(dir) + ":\"$PATH\" bash " +
                             q(root + "/scripts/bench-cycles.sh") + " " + q(build) + " 2 1 8");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("bench-cycles: skipped: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("/shared/assets/cornell-box/CornellBox-Original.obj is absent"),
            std::string::npos)
      << r.out;
}

// bench-converge.sh with a target that one sample per pixel reaches (a scaled-down run of the
// BENCHMARKS.md command): the ladder is the 1-spp rung alone, and the least-squares slope over
// one rung divided by zero; the row was printed with empty cells, a traceback on stderr, exit 0.
// Here a stand-in lucent writes the pilot's and the ladder's CSVs.
TEST(BenchScripts, ConvergeWithOneRungPrintsItsRow) {
  const std::string dir = lucent::test::temp_dir();
  const std::string build = dir + "/build";
  fs::create_directories(build);
  make_executable(build + "/lucent", R"(#!/bin/bash
csv="" ladder=""
while [[ $# -gt 0 ]]; do
  case $1 in --csv) csv=$2; shift ;; --spp-ladder) ladder=$2; shift ;; esac
  shift
done
echo setting,spp,seconds,samples_per_s,rmse,relmse,noise_relmse >"$csv"
if [[ $ladder == 8 ]]; then echo default,8,0.1,1e6,0.01,0.001,0.0001 >>"$csv"
else echo default,1,0.1,1e6,0.005,0.0015,0 >>"$csv"; fi
)");
  const std::string root = scratch_checkout(dir, {"bench-converge.sh"});
  fs::remove(root + "/scenes/needs-mesh.json");
  lucent::test::write_file(root + "/scenes/one.json",
                           R"({"film": {"width": 8, "height": 4}, "shapes": []})");
  ScriptRun r = run(root, "bash scripts/bench-converge.sh " + q(build) + " 1e-2 2 3");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("Traceback"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("| one | 8×4 | 64 | 1 | 0.0015 (0.00e+00) | 1 | 0.1 | 1.00 | nan | 0 | "
                       "reached at the first rung |"),
            std::string::npos)
      << r.out;
}

// bench-scenes.sh read lucent's summary line with `read`, which fails at an empty input: a run
// whose output had no summary line (LUCENT_BENCH_FLAGS=-q, or a changed format) made the script
// exit 1 after the table's header without a word.
TEST(BenchScripts, ScenesSaysWhenLucentPrintedNoSummary) {
  const std::string dir = lucent::test::temp_dir();
  const std::string build = dir + "/build";
  fs::create_directories(build);
  make_executable(build + "/lucent", "#!/bin/sh\nexit 0\n");
  const std::string root = scratch_checkout(dir, {"bench-scenes.sh"});
  fs::remove(root + "/scenes/needs-mesh.json");
  lucent::test::write_file(root + "/scenes/one.json",
                           R"({"film": {"width": 8, "height": 4}, "shapes": []})");
  ScriptRun r = run(root, "bash scripts/bench-scenes.sh " + q(build) + " 1 1");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("bench-scenes: one: no summary line in lucent's output"), std::string::npos)
      << r.err;
}

// test-intel-cpu.sh put its caches at "$PWD/$build/...": an absolute BUILD_DIR gave
// "<checkout>//abs/build/lucent-cache-intel", a directory made under the checkout; and its exec
// of the command skipped the trap that removes its ICD directory. Here a stand-in lucent lists
// an Intel CPU device and the command after -- prints the caches.
TEST(BenchScripts, IntelCpuCachesAreInTheBuildDirectory) {
  const std::string dir = lucent::test::temp_dir();
  fs::create_directories(dir + "/iocl");
  fs::create_directories(dir + "/tmp");
  lucent::test::write_file(dir + "/iocl/libintelocl.so", "");
  const std::string build = dir + "/a build";
  fs::create_directories(build);
  make_executable(build + "/lucent",
                  "#!/bin/sh\necho '  1  Intel(R) OpenCL   Some Xeon   CPU  (Intel(R) "
                  "Corporation)'\n");
  ScriptRun r = run(dir, "TMPDIR=" + q(dir + "/tmp") + " bash " +
                             q(lucent::test::source_path("scripts/test-intel-cpu.sh")) + " " +
                             q(dir + "/iocl") + " " + q(build) +
                             " -- sh -c 'echo \"$LUCENT_CACHE_DIR|$POCL_CACHE_DIR\"; exit 3'");
  EXPECT_EQ(r.status, 3) << r.err;  // the command's own status
  EXPECT_NE(r.out.find(build + "/lucent-cache-intel|" + build + "/pocl-cache\n"), std::string::npos)
      << r.out;
  // its ICD directory is removed (one was left in TMPDIR per run)
  EXPECT_TRUE(fs::is_empty(dir + "/tmp"));
}

}  // namespace test_scripts
