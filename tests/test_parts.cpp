// Sample-range renders and their merge (lucent/parts.hpp, docs/parts.md): parts of [0, N) merge
// into the accumulation of one N-spp render; the part file keeps the double sums bit for bit;
// overlapping or mismatched parts are refused with one line; a part cut short by SIGTERM records
// the range it completed and merges; mpirun -np 2 lucent-mpi renders the one-process image.
//
// Equality: the kernel sums each pass's samples in double on a device with fp64 (in float on one
// without) and the session adds the pass sums in double. Rendered with one sample per pass
// (pass_seconds tiny), a split render adds the same floats in another order, so the sums agree to
// double rounding (relative 1e-12). Through the command line the pass sizes (1, 4, 16, ... spp,
// tuned to the device's speed) differ between a part and the whole: with double pass sums the
// tolerance is relative 1e-12 on the sums, with float ones (a device without fp64) 1e-5, while a
// one-sample shift of the range (the error this guards against) changes them by the noise, ~10%
// (checked below, so the tolerance can fail).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <clocale>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <string>
#include <tuple>

#include "image/image_probe.hpp"
#include "lucent/compare.hpp"
#include "lucent/image.hpp"
#include "lucent/parts.hpp"
#include "lucent/version.hpp"
#include "render/part_write.hpp"
#include "render/resources.hpp"
#include "support.hpp"

namespace test_parts {

namespace {

namespace fs = std::filesystem;
using lucent::test::CommandResult;
using lucent::test::error_of;
using lucent::test::run_cli;

std::string q(const std::string& s) { return "'" + s + "'"; }

/// A diffuse sphere and a plane under a point light and a sky: every pixel noisy, 12x10.
std::string noisy_scene(const std::string& dir, int seed = 3, int width = 12) {
  std::string path = dir + "/scene.json";
  lucent::test::write_file(path, R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 30},
    "film": {"width": )" + std::to_string(width) +
                                     R"(, "height": 10},
    "integrator": {"type": "path", "spp": 8, "seed": )" +
                                     std::to_string(seed) + R"(},
    "materials": {"m": {"type": "diffuse", "albedo": [0.25, 0.5, 0.75]}},
    "shapes": [{"type": "triangles", "material": "m",
                "positions": [[-10,-10,0],[10,-10,0],[10,10,0],[-10,10,0]], "indices": [0,1,2, 0,2,3]},
               {"type": "sphere", "center": [0.3, 0.2, 0.5], "radius": 0.5, "material": "m"}],
    "lights": [{"type": "point", "position": [0.7, 0.4, 2.0], "intensity": [20, 20, 20]},
               {"type": "environment", "radiance": [0.3, 0.3, 0.3]}]
  })");
  return path;
}

/// Largest relative difference between two accumulations' sums (and sums of squares); the
/// counts must be equal.
double max_relative_difference(const lucent::Accumulation& a, const lucent::Accumulation& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.count, b.count);
  double worst = 0;
  for (int plane = 0; plane < 2; ++plane) {
    const std::vector<double>& x = plane ? a.sumsq : a.sum;
    const std::vector<double>& y = plane ? b.sumsq : b.sum;
    EXPECT_EQ(x.size(), y.size());
    for (size_t i = 0; i < x.size() && i < y.size(); ++i) {
      const double scale = std::max(std::abs(x[i]), std::abs(y[i]));
      if (scale > 0) worst = std::max(worst, std::abs(x[i] - y[i]) / scale);
    }
  }
  return worst;
}

bool bit_equal(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

/// The only line of stderr, which must start with "lucent: error: ".
std::string error_line(const CommandResult& r) {
  EXPECT_NE(r.status, 0);
  const std::string prefix = "lucent: error: ";
  EXPECT_EQ(r.err.rfind(prefix, 0), 0u) << r.err;
  EXPECT_EQ(lucent::test::count_lines(r.err), 1) << r.err;
  std::string line = r.err.substr(0, r.err.find('\n'));
  return line.size() > prefix.size() ? line.substr(prefix.size()) : line;
}

lucent::RenderPart render_range(lucent::Renderer& renderer, std::uint64_t begin,
                                std::uint64_t end) {
  renderer.reset(begin);
  renderer.render(end - begin);
  return lucent::make_part(renderer, {begin, end}, "scene.json");
}

TEST(Parts, MergedRangesEqualOneRenderToDoubleRounding) {
  std::string dir = lucent::test::temp_dir();
  lucent::SessionOptions so = lucent::test::session_options();
  so.pass_seconds = 1e-9;  // one sample per pass: the float pass sums are single samples
  lucent::Renderer renderer(so);
  renderer.set_scene(lucent::load_scene(noisy_scene(dir)));
  lucent::RenderPart whole = render_range(renderer, 0, 8);
  EXPECT_EQ(renderer.stats().passes, 8u);
  lucent::RenderPart a = render_range(renderer, 0, 3), b = render_range(renderer, 3, 8);
  EXPECT_EQ(a.info.scene_hash, whole.info.scene_hash);
  lucent::write_render_part(dir + "/a.exr", a);
  lucent::write_render_part(dir + "/b.exr", b);

  // the file keeps every double bit for bit
  lucent::RenderPart back = lucent::read_render_part(dir + "/b.exr");
  EXPECT_TRUE(bit_equal(back.acc.sum, b.acc.sum));
  EXPECT_TRUE(bit_equal(back.acc.sumsq, b.acc.sumsq));
  EXPECT_EQ(back.acc.count, b.acc.count);
  EXPECT_EQ(back.info.samples, (std::vector<lucent::SampleRange>{{3, 8}}));

  lucent::MergeReport m = lucent::merge_render_parts({dir + "/b.exr", dir + "/a.exr"});
  EXPECT_EQ(m.order, (std::vector<std::string>{dir + "/a.exr", dir + "/b.exr"}));
  EXPECT_EQ(m.merged.info.samples, (std::vector<lucent::SampleRange>{{0, 8}}));
  EXPECT_TRUE(m.missing.empty());
  EXPECT_EQ(m.min_spp, 8u);
  EXPECT_EQ(m.max_spp, 8u);
  EXPECT_LT(max_relative_difference(m.merged.acc, whole.acc), 1e-12);
  // the order the files are given in does not matter: the merge adds in sample order
  lucent::MergeReport m2 = lucent::merge_render_parts({dir + "/a.exr", dir + "/b.exr"});
  EXPECT_TRUE(bit_equal(m2.merged.acc.sum, m.merged.acc.sum));
  // a shifted range is a different image: the comparison can fail
  lucent::RenderPart shifted = render_range(renderer, 1, 9);
  EXPECT_GT(max_relative_difference(shifted.acc, whole.acc), 1e-3);
}

TEST(Parts, CommandLinePartsMergeIntoTheSingleRender) {
  std::string dir = lucent::test::temp_dir();
  std::string scene = noisy_scene(dir);
  for (const char* range : {"0:3", "3:8", "0:8", "1:9"}) {
    std::string name = std::string(range).replace(1, 1, "-");
    CommandResult r = run_cli("render " + q(scene) + " --samples " + range + " -q -o " +
                              q(dir + "/p" + name + ".exr"));
    ASSERT_EQ(r.status, 0) << r.err;
  }
  CommandResult r = run_cli("render " + q(scene) + " -q --spp 8 -o " + q(dir + "/single.exr"));
  ASSERT_EQ(r.status, 0) << r.err;
  r = run_cli("merge " + q(dir + "/p3-8.exr") + " " + q(dir + "/p0-3.exr") + " -o " +
              q(dir + "/merged.exr"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("samples [0, 8)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("min 8, mean 8.00, max 8"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;

  lucent::RenderPart merged = lucent::read_render_part(dir + "/merged.exr");
  lucent::RenderPart whole = lucent::read_render_part(dir + "/p0-8.exr");
  lucent::RenderPart shifted = lucent::read_render_part(dir + "/p1-9.exr");
  EXPECT_EQ(merged.info.scene_hash, whole.info.scene_hash);
  EXPECT_EQ(merged.info.seed, 3u);
  EXPECT_EQ(merged.info.integrator, "path");
  // the parts and the whole ran other pass sizes: with double pass sums (a device with fp64)
  // they agree to double rounding, with float ones to float rounding of the pass sums
  const double tolerance = lucent::select_device().fp64 ? 1e-12 : 1e-5;
  EXPECT_LT(max_relative_difference(merged.acc, whole.acc), tolerance);
  EXPECT_GT(max_relative_difference(shifted.acc, whole.acc), 1e-3);
  // against a plain render of 8 spp: the same mean, variance and counts
  lucent::RenderResult single = lucent::read_render(dir + "/single.exr");
  lucent::RenderResult mine = lucent::read_render(dir + "/merged.exr");
  // the seed and sampler that converge checks a reference by, as in the single render's file
  EXPECT_EQ(mine.seed, 3u);
  EXPECT_EQ(mine.sampler, single.sampler);
  EXPECT_FALSE(mine.sampler.empty());
  EXPECT_EQ(merged.info.sampler, single.sampler);
  ASSERT_EQ(single.mean.rgb.size(), mine.mean.rgb.size());
  EXPECT_EQ(single.samples, mine.samples);
  for (size_t i = 0; i < single.mean.rgb.size(); ++i) {
    EXPECT_NEAR(mine.mean.rgb[i], single.mean.rgb[i], 1e-5 * std::abs(single.mean.rgb[i]) + 1e-7);
    EXPECT_NEAR(mine.variance.rgb[i], single.variance.rgb[i],
                1e-4 * std::abs(single.variance.rgb[i]) + 1e-7);
  }
  // .pfm and .png outputs: the mean
  r = run_cli("merge -q " + q(dir + "/p0-3.exr") + " " + q(dir + "/p3-8.exr") + " -o " +
              q(dir + "/merged.pfm"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(lucent::read_image(dir + "/merged.pfm").rgb, mine.mean.rgb);
}

TEST(Parts, OverlapsAndMismatchesAreOneLineErrors) {
  std::string dir = lucent::test::temp_dir();
  std::string scene = noisy_scene(dir);
  std::string other_dir = dir + "/other";
  fs::create_directories(other_dir);
  std::string other = noisy_scene(other_dir, 3, 14);
  auto part = [&](const std::string& s, const std::string& range, const std::string& out,
                  const std::string& extra = "") {
    CommandResult r = run_cli("render " + q(s) + " -q --samples " + range + " " + extra + " -o " +
                              q(dir + "/" + out));
    EXPECT_EQ(r.status, 0) << r.err;
    return q(dir + "/" + out);
  };
  std::string a = part(scene, "0:4", "a.exr"), b = part(scene, "2:6", "b.exr");
  std::string c = part(scene, "4:6", "c.exr", "--seed 9");
  std::string d = part(other, "4:6", "d.exr");
  // (the full kernel with fast math: the program CliErrors.IgnoredOptionsAreRefused builds too)
  std::string f = part(scene, "6:8", "f.exr", "--fast-math --no-specialize");
  part(scene, "6:8", "g0.exr");
  // (the full kernel: a specialised one of the direct integrator cost CI a cold kernel build)
  std::string e = part(scene, "4:6", "e.exr", "--integrator direct --no-specialize");
  const std::string out = dir + "/out.exr";
  EXPECT_EQ(error_line(run_cli("merge " + a + " " + b + " -o " + q(out))),
            dir + "/b.exr: samples [2, 6) overlap " + dir + "/a.exr's [0, 4)");
  EXPECT_EQ(error_line(run_cli("merge " + a + " " + c + " -o " + q(out))),
            dir + "/c.exr: seed 9 differs from " + dir + "/a.exr's 3");
  EXPECT_EQ(error_line(run_cli("merge " + a + " " + d + " -o " + q(out))),
            dir + "/d.exr: film 14x10 differs from " + dir + "/a.exr's 12x10");
  EXPECT_EQ(error_line(run_cli("merge " + a + " " + e + " -o " + q(out))),
            dir + "/e.exr: integrator direct differs from " + dir + "/a.exr's path");
  EXPECT_NE(error_line(run_cli("merge " + a + " " + f + " -o " + q(out)))
                .find(dir + "/f.exr: scene hash "),
            std::string::npos);
  // another kernel source (a copy of kernels/ with one comment more): the hash covers the
  // source, so parts of two estimators do not mix (they merged before)
  fs::copy(lucent::test::source_path("kernels"), dir + "/k", fs::copy_options::recursive);
  std::ofstream(dir + "/k/megakernel.cl", std::ios::app) << "\n/* another kernel */\n";
  CommandResult kr = run_cli("render " + q(scene) + " -q --samples 6:8 -o " + q(dir + "/k.exr"),
                             "LUCENT_KERNEL_DIR=" + q(dir + "/k"));
  ASSERT_EQ(kr.status, 0) << kr.err;
  EXPECT_NE(error_line(run_cli("merge " + a + " " + q(dir + "/k.exr") + " -o " + q(out)))
                .find("(another scene, camera, film, integrator setting, build option or kernel "
                      "source)"),
            std::string::npos);
  // a part of another lucent version (its header rewritten)
  lucent::RenderPart old = lucent::read_render_part(dir + "/g0.exr");
  old.info.version = "0.0.1";
  lucent::write_render_part(dir + "/v.exr", old);
  EXPECT_EQ(error_line(run_cli("merge " + a + " " + q(dir + "/v.exr") + " -o " + q(out))),
            dir + "/v.exr: made by lucent 0.0.1, " + dir + "/a.exr by lucent " + lucent::kVersion +
                " (their kernels may differ: render every part with one version)");
  EXPECT_EQ(error_line(run_cli("merge " + a + " " + a + " -o " + q(out))),
            dir + "/a.exr: given twice (as " + dir + "/a.exr)");
  fs::create_symlink(dir + "/a.exr", dir + "/link.exr");
  fs::create_hard_link(dir + "/a.exr", dir + "/hard.exr");
  EXPECT_EQ(error_line(run_cli("merge " + a + " " + q(dir + "/link.exr") + " -o " + q(out))),
            dir + "/link.exr: given twice (as " + dir + "/a.exr)");
  EXPECT_EQ(error_line(run_cli("merge " + q(dir + "/hard.exr") + " " + a + " -o " + q(out))),
            dir + "/a.exr: given twice (as " + dir + "/hard.exr)");
  // a render EXR that is not a part
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --spp 2 -o " + q(dir + "/plain.exr")).status, 0);
  EXPECT_EQ(error_line(run_cli("merge " + a + " " + q(dir + "/plain.exr") + " -o " + q(out))),
            dir + "/plain.exr: not a lucent part file (no lucent.format attribute; render parts " +
                "with `lucent render --samples A:B`)");
  EXPECT_EQ(error_line(run_cli("merge " + a + " -o " + a)),
            dir + "/a.exr: is an input of the merge; refusing to overwrite it");
  EXPECT_FALSE(fs::exists(out));
  // bad ranges and combinations
  EXPECT_EQ(error_line(run_cli("render " + q(scene) + " --samples 5:5 -o " + q(out))),
            "--samples '5:5': need 0 <= A < B <= 4294967296");
  EXPECT_EQ(error_line(run_cli("render " + q(scene) + " --samples 3 -o " + q(out))),
            "--samples '3': expected A:B, the sample indices [A, B) in decimal");
  // plain decimal, as the integer options (010:020 read 10:20 where --spp 010 is refused)
  EXPECT_EQ(error_line(run_cli("render " + q(scene) + " --samples 010:020 -o " + q(out))),
            "--samples '010:020': expected A:B, the sample indices [A, B) in decimal");
  EXPECT_EQ(error_line(run_cli("merge --expect 0:08 " + a + " -o " + q(out))),
            "--expect '0:08': expected A:B, the sample indices [A, B) in decimal");
  EXPECT_EQ(error_line(run_cli("render " + q(scene) + " --samples 0:4 -o " + q(dir + "/x.png"))),
            dir + "/x.png: --samples writes a part file: use an .exr output");
  EXPECT_EQ(error_line(run_cli("render " + q(scene) + " --samples 0:4 --spp 4 -o " + q(out))),
            "--samples and --spp cannot be combined");
  // missing ranges: a warning naming them, or an error with --complete (nothing written)
  std::string g = part(scene, "6:8", "g.exr");
  EXPECT_EQ(error_line(run_cli("merge --complete " + a + " " + g + " -o " + q(out))),
            "merge: samples [4, 6) are missing (--complete)");
  EXPECT_FALSE(fs::exists(out));
  // --expect: the range the parts should hold together, so that a last part that was never
  // written is missing too (the default range ends where the last part given ends)
  EXPECT_EQ(error_line(run_cli("merge --complete --expect 0:10 " + a + " " + g + " -o " + q(out))),
            "merge: samples [4, 6), [8, 10) are missing (--complete)");
  EXPECT_EQ(error_line(run_cli("merge --expect 0:6 " + a + " " + g + " -o " + q(out))),
            "merge: the parts hold samples [6, 8) outside --expect [0, 6) (they hold [0, 4), "
            "[6, 8))");
  // only what lies outside (it named all of the parts' samples)
  EXPECT_EQ(error_line(run_cli("merge --expect 2:7 " + a + " " + g + " -o " + q(out))),
            "merge: the parts hold samples [0, 2), [7, 8) outside --expect [2, 7) (they hold "
            "[0, 4), [6, 8))");
  EXPECT_FALSE(fs::exists(out));
  CommandResult r = run_cli("merge " + a + " " + g + " -o " + q(out));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("lucent: warning: samples [4, 6) are missing"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("min 6, mean 6.00, max 6"), std::string::npos) << r.err;
}

/// A part of a 1x1 film made without rendering: `samples` of `requested`, all of them finite.
lucent::RenderPart handmade_part(const std::vector<lucent::SampleRange>& samples,
                                 lucent::SampleRange requested) {
  lucent::RenderPart p;
  p.info.width = p.info.height = 1;
  p.info.seed = 1;
  p.info.integrator = "path";
  p.info.version = lucent::kVersion;
  p.info.scene_hash = 7;
  p.info.scene = "scene.json";
  p.info.samples = samples;
  p.info.requested = {requested};
  p.acc.width = p.acc.height = 1;
  p.acc.sum = p.acc.sumsq = {0.5, 0.5, 0.5};
  std::uint64_t n = 0;
  for (const lucent::SampleRange& r : samples) n += r.end - r.begin;
  p.acc.count = {static_cast<std::uint32_t>(n)};
  return p;
}

// A part's time is written in full: the attribute was printed into 64 characters, so a time above
// 1e56 (a part file's lucent.seconds of 1e308, which reading takes) was written cut to its first
// 63 digits, 1e308 as 1.0000000000000000109e62, without a word.
TEST(Parts, LargeTimesAreWrittenInFull) {
  const std::string dir = lucent::test::temp_dir();
  for (const double seconds : {1e308, 1.7976931348623157e308, 123456.5}) {
    lucent::RenderPart p = handmade_part({{0, 4}}, {0, 4});
    p.info.seconds = seconds;
    lucent::write_render_part(dir + "/p.exr", p);
    EXPECT_EQ(lucent::read_part_info(dir + "/p.exr").seconds, seconds);
  }
}

// A part holds at most 2^24 samples (--samples), but parts together may hold up to 2^32:
// `merge --expect` took the per-part limit, so a Slurm job of more than 2^24 spp
// (scripts/slurm/submit.sh passes --expect 0:SPP) rendered every part, then failed to merge.
TEST(Parts, ExpectMayCoverMoreSamplesThanOnePart) {
  const std::string dir = lucent::test::temp_dir();
  const std::uint64_t m = 1ull << 24;
  lucent::write_render_part(dir + "/a.exr", handmade_part({{0, m}}, {0, m}));
  lucent::write_render_part(dir + "/b.exr", handmade_part({{m, 2 * m}}, {m, 2 * m}));
  const std::string parts =
      q(dir + "/a.exr") + " " + q(dir + "/b.exr") + " -o " + q(dir + "/o.exr");
  CommandResult r = run_cli("merge --complete --expect 0:33554432 " + parts);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(lucent::read_render_part(dir + "/o.exr").acc.count,
            (std::vector<std::uint32_t>{1u << 25}));
  EXPECT_EQ(error_line(run_cli("merge --complete --expect 0:33554433 " + parts)),
            "merge: samples [33554432, 33554433) are missing (--complete)");
  EXPECT_EQ(error_line(run_cli("merge --expect 0:4294967297 " + parts)),
            "--expect '0:4294967297': need 0 <= A < B <= 4294967296");
  // one part is still limited
  EXPECT_EQ(error_line(run_cli("render " + q(dir + "/none.json") + " --samples 0:16777217 -o " +
                               q(dir + "/x.exr"))),
            "--samples '0:16777217': at most 16777216 samples per part");
}

// check_merge_coverage refuses the expected range the command line's A:B refuses: an inverted
// one ({8, 0}) was taken, and every sample was "outside" it twice, below its begin and above its
// end ("the parts hold samples [0, 4), [0, 4) outside --expect [8, 0)"; the API tester's find).
TEST(Parts, MergeCoverageRefusesAnEmptyOrInvertedExpect) {
  lucent::MergeReport r;
  r.merged.info.samples = {{0, 4}};
  auto coverage = [&](lucent::SampleRange expect) {
    return lucent::test::error_of(
        [&] { lucent::check_merge_coverage(r, expect, false, "--expect", "--complete"); });
  };
  EXPECT_EQ(coverage({8, 0}), "merge: --expect [8, 0): need 0 <= begin < end <= 4294967296");
  EXPECT_EQ(coverage({4, 4}), "merge: --expect [4, 4): need 0 <= begin < end <= 4294967296");
  EXPECT_EQ(coverage({0, (1ull << 32) + 1}),
            "merge: --expect [0, 4294967297): need 0 <= begin < end <= 4294967296");
  // a range below and above the parts' is each side once
  r.merged.info.samples = {{0, 8}};
  EXPECT_EQ(coverage({2, 6}),
            "merge: the parts hold samples [0, 2), [6, 8) outside --expect [2, 6) (they hold "
            "[0, 8))");
  r.merged.info.samples = {{0, 4}};
  EXPECT_EQ(coverage({0, 8}), "");
  EXPECT_EQ(r.missing, (std::vector<lucent::SampleRange>{{4, 8}}));
}

// The estimate of a part's write takes no film of a negative or zero size (-1 x 5 was 0 x 5:
// 1 MiB; the API tester's find).
TEST(Parts, PartWriteBytesRefusesAFilmSizeNotPositive) {
  EXPECT_EQ(lucent::test::error_of([] { lucent::part_write_bytes(-1, 5); }),
            "part_write_bytes: the film size must be positive, got -1x5");
  EXPECT_EQ(lucent::test::error_of([] { lucent::part_write_bytes(4, 0); }),
            "part_write_bytes: the film size must be positive, got 4x0");
  EXPECT_GT(lucent::part_write_bytes(1, 1), 0u);
}

// A compression outside the enum (a cast integer, as a binding may pass) was taken as zip, by the
// estimate and the writer alike; both refuse it now, the writer before writing anything.
TEST(Parts, AnUnknownCompressionIsRefused) {
  const auto bad = static_cast<lucent::PartCompression>(7);
  EXPECT_EQ(lucent::test::error_of([&] { lucent::part_write_bytes(4, 4, bad); }),
            "part_write_bytes: unknown part compression 7 (zip or piz)");
  const std::string path = lucent::test::temp_dir() + "/p.exr";
  EXPECT_EQ(lucent::test::error_of([&] {
              lucent::write_render_part(path, handmade_part({{0, 4}}, {0, 4}), bad);
            }),
            path + ": cannot write part: unknown part compression 7 (zip or piz)");
  EXPECT_FALSE(std::filesystem::exists(path));
}

// Misuse of the library's merger and parts by another tool is a lucent::Error: add() after
// add_header() read empty sums as a film's (a segfault), finish() after headers alone returned a
// 0x0 image, and part_result read past the vectors of a part whose sizes disagree.
TEST(Parts, MergerAndPartsMisusedAreErrors) {
  const lucent::RenderPart a = handmade_part({{0, 4}}, {0, 4}), b = handmade_part({{4, 8}}, {4, 8});
  lucent::PartMerger headers;
  headers.add_header("a", a.info);
  EXPECT_EQ(error_of([&] { headers.add("b", b); }),
            "b: PartMerger: add() after add_header(): a merger checks headers or adds parts, not "
            "both");
  EXPECT_EQ(error_of([&] { headers.finish(); }),
            "merge: no parts added (add_header() checks headers, add() adds parts)");
  // nor the other way round: the header's samples were never added, and finish() said "missing
  // none" (the API campaign)
  lucent::PartMerger added;
  added.add("a", a);
  EXPECT_EQ(error_of([&] { added.add_header("b", b.info); }),
            "b: PartMerger: add_header() after add(): a merger checks headers or adds parts, not "
            "both");
  EXPECT_EQ(added.finish().merged.info.samples.size(), 1u);
  // a merger spent by finish() says so (add() said "add() after add_header()", finish() "no
  // parts added")
  lucent::PartMerger spent;
  spent.add("a", a);
  EXPECT_EQ(spent.finish().merged.info.samples.size(), 1u);
  const char* after = " after finish(): a merger gives its merged part once (use a new one)";
  EXPECT_EQ(error_of([&] { spent.add("b", b); }), std::string("PartMerger: add()") + after);
  EXPECT_EQ(error_of([&] { spent.add("b", lucent::RenderPart(b)); }),
            std::string("PartMerger: add()") + after);
  EXPECT_EQ(error_of([&] { spent.add_header("b", b.info); }),
            std::string("PartMerger: add_header()") + after);
  EXPECT_EQ(error_of([&] { spent.finish(); }), std::string("PartMerger: finish()") + after);
  lucent::RenderPart bad = a;
  bad.acc.width = bad.acc.height = 512;
  EXPECT_EQ(error_of([&] { lucent::part_result(bad); }),
            "part_result: inconsistent part (film and accumulation sizes differ)");
  bad = a;
  bad.acc.count.clear();
  EXPECT_EQ(error_of([&] { lucent::part_result(bad); }),
            "part_result: inconsistent part (film and accumulation sizes differ)");
  lucent::RenderPart empty;
  lucent::PartMerger parts;
  EXPECT_EQ(error_of([&] { parts.add("e", empty); }), "e: the part's film 0x0 has no pixels");
  parts.add("a", a);
  parts.add("b", b);
  EXPECT_EQ(parts.finish().merged.acc.count, (std::vector<std::uint32_t>{8}));
}

// A part made in memory (a library caller's) is checked as reading checks a file: a part whose
// own ranges were out of order merged with another overlapping them, counting a sample twice,
// and write_render_part wrote headers and sums that read_render_part then refused (a part of no
// samples, make_part's before a render, wrote an attribute read back as a NUL, which cut the
// reader's message off). The adversarial API tester's finds.
TEST(Parts, PartsMadeInMemoryAreCheckedAsFilesAre) {
  const std::string dir = lucent::test::temp_dir();
  const std::string file = dir + "/p.exr";
  struct Case {
    std::function<void(lucent::RenderPart&)> alter;
    std::string message;
  };
  const Case cases[] = {
      {[](lucent::RenderPart& p) {
         p.info.samples = p.info.requested = {{10, 14}, {0, 4}};
       },
       "the part's samples [10, 14), [0, 4): ranges must be non-empty, sorted, disjoint and end at "
       "2^32 at most"},
      {[](lucent::RenderPart& p) {
         p.info.samples = p.info.requested = {{0, 4}, {2, 6}};
       },
       "the part's samples [0, 4), [2, 6): ranges must be non-empty, sorted, disjoint and end at "
       "2^32 at most"},
      {[](lucent::RenderPart& p) {
         p.info.requested = {{0, 1ull << 40}};
       },
       "the part's requested [0, 1099511627776): ranges must be non-empty, sorted, disjoint and "
       "end at 2^32 at most"},
      {[](lucent::RenderPart& p) { p.info.requested.clear(); },
       "the part requests no sample range"},
      {[](lucent::RenderPart& p) { p.info.integrator = "bogus"; },
       "the part's integrator 'bogus' is unknown"},
      {[](lucent::RenderPart& p) { p.info.display.gamma = std::nan(""); },
       "the part's display gamma must be finite and > 0, its exposure finite"},
      {[](lucent::RenderPart& p) { p.acc.sum[1] = std::nan(""); },
       "pixel 0, 0 holds an invalid sum (not finite, or a negative sum of squares)"},
      {[](lucent::RenderPart& p) { p.acc.sumsq[2] = -1; },
       "pixel 0, 0 holds an invalid sum (not finite, or a negative sum of squares)"},
      {[](lucent::RenderPart& p) { p.acc.sum[0] = 4e39; },
       "pixel 0, 0: its mean or sample variance is beyond a float's range (no render's is)"}};
  for (const Case& c : cases) {
    lucent::RenderPart p = handmade_part({{0, 4}}, {0, 4});
    c.alter(p);
    EXPECT_EQ(error_of([&] { lucent::write_render_part(file, p); }),
              file + ": cannot write part: " + c.message);
    EXPECT_FALSE(fs::exists(file)) << c.message;
    lucent::PartMerger merger;
    EXPECT_EQ(error_of([&] { merger.add("p", p); }), "p: " + c.message);
    lucent::PartMerger headers;
    if (c.message.find("pixel 0, 0") == std::string::npos) {
      EXPECT_EQ(error_of([&] { headers.add_header("p", p.info); }), "p: " + c.message);
    }
  }
  // an overlap within one part no longer hides from the merger: [0, 4) and [2, 3) were taken
  lucent::PartMerger merger;
  lucent::RenderPart unsorted = handmade_part({{10, 14}, {0, 4}}, {0, 16});
  EXPECT_NE(error_of([&] { merger.add("a", unsorted); }), "");
  // a part of no samples: refused by the writer (its samples attribute read back as "\0")
  lucent::RenderPart none = handmade_part({}, {0, 4});
  EXPECT_EQ(error_of([&] { lucent::write_render_part(file, none); }),
            file + ": cannot write part: it holds no samples (render before make_part)");
  EXPECT_FALSE(fs::exists(file));
  // the good part writes and reads back
  lucent::write_render_part(file, handmade_part({{0, 4}}, {0, 4}));
  EXPECT_EQ(lucent::read_render_part(file).acc.count, (std::vector<std::uint32_t>{4}));
}

// Parts of two samplers (their headers say which) were refused only by their scene hashes, as
// "another scene, camera, film, integrator setting, build option or kernel source", although
// each header names its sampler: the merge names it now, as it names the seed. A part of lucent
// before 24 Nov 2026 records no sampler, and merges with either.
TEST(Parts, PartsOfTwoSamplersAreRefusedByName) {
  lucent::RenderPart a = handmade_part({{0, 4}}, {0, 4}), b = handmade_part({{4, 8}}, {4, 8});
  a.info.sampler = "sobol";
  b.info.sampler = "independent";
  lucent::PartMerger m;
  m.add("a.exr", a);
  EXPECT_EQ(error_of([&] { m.add("b.exr", b); }),
            "b.exr: sampler independent differs from a.exr's sobol");
  b.info.sampler.clear();  // an older part file
  m.add("b.exr", b);
  lucent::MergeReport r = m.finish();
  EXPECT_EQ(r.merged.info.sampler, "sobol");
  EXPECT_EQ(r.merged.info.samples, (std::vector<lucent::SampleRange>{{0, 8}}));
}

// A part's header may list many ranges (a merge of parts with gaps between them, or a file made
// to hurt). The overlap check ran a loop over every pair of ranges: two crafted part files of
// 0.5 MB each (4*10^4 interleaved ranges) took 1.7 s to merge, and ten times as many ranges
// would take minutes. It is one pass now; it must still find the first overlap, as the pair loop
// did. And a list of ranges in a message stays one short line.
TEST(Parts, ManyRangesAreCheckedInOnePassAndListedBriefly) {
  auto header = [](std::vector<lucent::SampleRange> samples) {
    lucent::PartInfo info;
    info.width = info.height = 1;
    info.seed = 1;
    info.integrator = "path";
    info.version = lucent::kVersion;
    info.requested = {{0, samples.empty() ? 1 : samples.back().end}};
    info.samples = std::move(samples);
    return info;
  };
  // the first range of the second part that overlaps one of the first, and the first of those
  // it overlaps, by the pair loop (the definition)
  auto expected = [](const std::vector<lucent::SampleRange>& second,
                     const std::vector<lucent::SampleRange>& first) -> std::string {
    for (const lucent::SampleRange& x : second)
      for (const lucent::SampleRange& y : first)
        if (x.begin < y.end && y.begin < x.end)
          return "b: samples " + lucent::range_text(x) + " overlap a's " + lucent::range_text(y);
    return "";
  };
  // random sorted disjoint lists of up to 4 short ranges in [0, 40): every way two such lists
  // can meet, or not
  std::uint64_t state = 12345;
  auto next = [&](std::uint64_t n) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return (state >> 33) % n;
  };
  auto random_ranges = [&] {
    std::vector<lucent::SampleRange> rs;
    std::uint64_t at = next(10);
    for (std::uint64_t k = 0, n = 1 + next(4); k < n && at < 40; ++k) {
      const std::uint64_t end = at + 1 + next(3);
      rs.push_back({at, end});
      at = end + next(12);
    }
    return rs;
  };
  int overlapping = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const std::vector<lucent::SampleRange> a = random_ranges(), b = random_ranges();
    lucent::PartMerger merger;
    merger.add_header("a", header(a));
    const std::string want = expected(b, a);
    EXPECT_EQ(error_of([&] { merger.add_header("b", header(b)); }), want)
        << "a: " << lucent::ranges_text(a) << "; b: " << lucent::ranges_text(b);
    overlapping += !want.empty();
  }
  EXPECT_GT(overlapping, 200);  // both outcomes are exercised
  EXPECT_LT(overlapping, 1800);

  // 10^5 interleaved ranges each (the pair loop: 10^10 comparisons), overlapping only at the end
  const std::uint64_t n = 100000;
  std::vector<lucent::SampleRange> even, odd;
  for (std::uint64_t k = 0; k < n; ++k) {
    even.push_back({2 * k, 2 * k + 1});
    odd.push_back({2 * k + 1, 2 * k + 2});
  }
  even.push_back({2 * n, 2 * n + 2});
  odd.push_back({2 * n + 1, 2 * n + 3});
  lucent::PartMerger merger;
  merger.add_header("a", header(even));
  EXPECT_EQ(error_of([&] { merger.add_header("b", header(odd)); }),
            "b: samples [200001, 200003) overlap a's [200000, 200002)");

  // (at most 200 characters of it compared, so that a failure prints a short line too)
  EXPECT_EQ(lucent::ranges_text(even).substr(0, 200),
            "[0, 1), [2, 3), [4, 5), [6, 7), [8, 9), [10, 11), ..., [200000, 200002) (100001 "
            "ranges)");
  const std::vector<lucent::SampleRange> eight(even.begin(), even.begin() + 8);
  EXPECT_EQ(lucent::ranges_text(eight),
            "[0, 1), [2, 3), [4, 5), [6, 7), [8, 9), [10, 11), [12, 13), [14, 15)");

  // through the command line: parts of a 1x1 film whose headers list 2000 ranges each merge,
  // and the warning naming the samples one of them misses is one short line
  std::string dir = lucent::test::temp_dir();
  for (std::uint64_t f = 0; f < 2; ++f) {
    std::vector<lucent::SampleRange> samples;
    for (std::uint64_t k = 0; k < 2000; ++k) samples.push_back({2 * k + f, 2 * k + f + 1});
    lucent::write_render_part(dir + "/p" + std::to_string(f) + ".exr",
                              handmade_part(samples, {0, 4000}));
  }
  const std::string out = dir + "/out.exr";
  CommandResult one = run_cli("merge " + q(dir + "/p0.exr") + " -o " + q(out));
  ASSERT_EQ(one.status, 0) << one.err;
  const std::string missing =
      "lucent: warning: samples [1, 2), [3, 4), [5, 6), [7, 8), [9, 10), [11, 12), ..., "
      "[3999, 4000) (2000 ranges) are missing";
  EXPECT_EQ(one.err.substr(0, missing.size()), missing) << one.err;
  EXPECT_LT(one.err.size(), 1000u) << one.err;
  CommandResult both =
      run_cli("merge " + q(dir + "/p0.exr") + " " + q(dir + "/p1.exr") + " -o " + q(out));
  ASSERT_EQ(both.status, 0) << both.err;
  EXPECT_EQ(lucent::read_render_part(out).info.samples,
            (std::vector<lucent::SampleRange>{{0, 4000}}));
  EXPECT_EQ(lucent::read_render_part(out).acc.count, (std::vector<std::uint32_t>{4000}));
}

// merge's output is checked before any part is read (an unknown format was refused only after
// every part had been read and added): here the parts do not even exist, so any other error
// would name them.
TEST(Parts, MergeChecksItsOutputBeforeReadingTheParts) {
  const std::string dir = lucent::test::temp_dir();
  const std::string parts = q(dir + "/missing-a.exr") + " " + q(dir + "/missing-b.exr");
  EXPECT_EQ(error_line(run_cli("merge " + parts + " -o " + q(dir + "/out.txt"))),
            dir + "/out.txt: unknown output format '.txt' (use .png, .pfm or .exr)");
  EXPECT_EQ(error_line(run_cli("merge " + parts + " -o " + q(dir + "/no/dir/out.exr"))),
            dir + "/no/dir/out.exr: cannot write output (No such file or directory)");
  fs::create_directories(dir + "/d.exr");
  EXPECT_EQ(error_line(run_cli("merge " + parts + " -o " + q(dir + "/d.exr"))),
            dir + "/d.exr: is a directory");
  EXPECT_FALSE(fs::exists(dir + "/out.txt"));
}

// A damaged part file (an attribute edited, or not an EXR at all) is refused by merge with one
// line naming the file, the attribute and what is wrong with it, and nothing is written. Each
// copy of a good part has part of one attribute's value replaced by as many other bytes.
// A session holding an adaptive render has no range of sample indices to make a part of: it once
// made a part of zero sums that claimed the render's range.
TEST(Parts, AdaptiveSessionMakesNoPart) {
  lucent::Renderer renderer(lucent::test::session_options());
  renderer.set_scene(lucent::load_scene(noisy_scene(lucent::test::temp_dir())));
  lucent::AdaptiveOptions ao;
  ao.budget_spp = 8;
  renderer.render_adaptive(ao);
  const std::string msg = error_of([&] { lucent::make_part(renderer, {0, 8}, "scene.json"); });
  EXPECT_NE(msg.find("the session holds an adaptive render"), std::string::npos) << msg;
}

// Reading a part is checked against the host's memory before it decodes (about 256 bytes per
// pixel): a merge of parts of the largest films could allocate tens of GB unchecked. Here the
// limit is shrunk so that a 12x10 part stands for a huge one.
TEST(Parts, ReadingAPartChecksItsMemoryFirst) {
  const std::string dir = lucent::test::temp_dir();
  lucent::Renderer renderer(lucent::test::session_options());
  renderer.set_scene(lucent::load_scene(noisy_scene(dir)));
  lucent::write_render_part(dir + "/p.exr", render_range(renderer, 0, 2));
  lucent::render_detail::DeviceLimits lim;
  lim.host_mem = 16 << 10;
  lucent::render_detail::ScopedLimitOverride o(lim);
  std::string msg = error_of([&] { lucent::read_render_part(dir + "/p.exr"); });
  EXPECT_NE(msg.find(dir + "/p.exr: reading this 12x10 part needs about "), std::string::npos)
      << msg;
  EXPECT_NE(msg.find("more than the limit of 16.0 KiB"), std::string::npos) << msg;
  // a file larger than the limit by itself is refused before it is read
  lim.host_mem = 1 << 10;
  lucent::render_detail::ScopedLimitOverride tiny(lim);
  msg = error_of([&] { lucent::read_part_info(dir + "/p.exr"); });
  EXPECT_NE(msg.find("is larger than the memory limit of 1.0 KiB"), std::string::npos) << msg;
}

/// Samples [0, spp) of noisy_scene at width x height, as a part.
lucent::RenderPart noisy_part(const std::string& dir, int width, int height, std::uint64_t spp) {
  lucent::Scene scene = lucent::load_scene(noisy_scene(dir));
  scene.film.width = width;
  scene.film.height = height;
  lucent::Renderer renderer(lucent::test::session_options());
  renderer.set_scene(scene);
  return render_range(renderer, 0, spp);
}

constexpr lucent::PartCompression kCompressions[] = {lucent::PartCompression::zip,
                                                     lucent::PartCompression::piz};
const char* name_of(lucent::PartCompression c) {
  return c == lucent::PartCompression::zip ? "ZIP" : "PIZ";
}

// What reading a 640x480 part file takes, measured in a child process, against what the readers
// count before they decode it (image_detail::exr_decode_bytes_per_pixel, and the file):
// read_render_part, and read_render (`lucent compare` and `converge --reference` given a part),
// whose count of 128 bytes a pixel for any OpenEXR was half of what a part's 19 channels took.
// ZIP, and PIZ (a checkpoint's).
TEST(Parts, ReadingAPartStaysWithinTheReadersCount) {
  if (lucent::test::kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer's memory is in the peak";
  const std::string dir = lucent::test::temp_dir();
  const lucent::RenderPart part = noisy_part(dir, 640, 480, 1);
  const std::string path = dir + "/p.exr";
  const double mib = 1048576.0;
  for (lucent::PartCompression c : kCompressions) {
    SCOPED_TRACE(name_of(c));
    lucent::write_render_part(path, part, c);
    const std::string bytes = lucent::test::read_file(path);
    const lucent::image_detail::Probe p = lucent::image_detail::probe_image(
        reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), path, 1 << 24);
    EXPECT_EQ(p.channels, 19);
    const double count =
        640.0 * 480 * double(lucent::image_detail::exr_decode_bytes_per_pixel(p)) + bytes.size();
    const double as_part = lucent::test::child_peak_bytes(
        [&] { return lucent::read_render_part(path).acc.width == 640; });
    const double as_image =
        lucent::test::child_peak_bytes([&] { return lucent::read_render(path).mean.width == 640; });
    ASSERT_GT(as_part, 0) << "the child process could not measure its peak";
    ASSERT_GT(as_image, 0) << "the child process could not measure its peak";
    for (const double peak : {as_part, as_image}) {
      EXPECT_LE(peak, count) << "peak " << peak / mib << " MiB, counted " << count / mib << " MiB";
      EXPECT_GE(peak, 0.6 * count)
          << "peak " << peak / mib << " MiB, counted " << count / mib << " MiB";
    }
  }
}

// A part file keeps its sums bit for bit in both compressions (PIZ, a checkpoint's, handles the
// 32-bit words as pairs of 16-bit values), and checks them: its attribute lucent.checksum. A PIZ
// chunk has no check of its own (ZIP's has Adler-32), so a damaged one that still decoded gave
// other sums without a word; a damaged file now reads as its sums or is refused in one line.
// A part file's attributes and a caustics render's lucent.light_mean_var are read and written in
// the "C" locale, whatever the process's: after a library caller's setlocale to a decimal-comma
// locale (Qt applications do it at start), every part file was refused ("attribute lucent.display:
// invalid 'srgb,2.2,0,clamp'") and a caustics EXR was written with "9,92e-07", which the command
// line then refused (the fuzz runner's find). A comma locale installed, or made by localedef
// into a temporary directory (LOCPATH); skipped when there is none.
TEST(Parts, AttributesIgnoreTheProcessLocale) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir), part = dir + "/p.exr";
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples 0:4 -o " + q(part)).status, 0);
  const std::string before = std::setlocale(LC_ALL, nullptr);
  struct Restore {
    std::string name;
    ~Restore() { std::setlocale(LC_ALL, name.c_str()); }
  } restore{before};
  const auto comma = [] {
    return std::setlocale(LC_ALL, nullptr) && std::string(std::localeconv()->decimal_point) == ",";
  };
  bool found = false;
  for (const char* name : {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8"})
    if (std::setlocale(LC_ALL, name) && comma()) {
      found = true;
      break;
    }
  if (!found &&
      std::system(("localedef -i de_DE -f UTF-8 " + q(dir + "/de_DE.UTF-8") + " >/dev/null 2>&1")
                      .c_str()) == 0) {
    ::setenv("LOCPATH", dir.c_str(), 1);
    found = std::setlocale(LC_ALL, "de_DE.UTF-8") && comma();
    ::unsetenv("LOCPATH");
  }
  if (!found) GTEST_SKIP() << "no locale with a decimal comma here, and localedef made none";
  char probe[16];
  std::snprintf(probe, sizeof probe, "%.1f", 0.5);
  ASSERT_STREQ(probe, "0,5");

  const lucent::PartInfo info = lucent::read_part_info(part);
  EXPECT_EQ(info.display.gamma, 2.2);
  EXPECT_EQ(lucent::read_render_part(part).info.samples, info.samples);
  // a render's light part of the image mean, written and read back
  lucent::RenderResult r;
  r.mean = lucent::Image{2, 1, std::vector<float>(6, 0.5f)};
  r.variance = r.mean;
  r.samples = {4, 4};
  r.light_mean_variance = lucent::LightMeanVariance{{0.5, 0.25, 1e-7}, {0.125, 0.5, 0.75}};
  lucent::write_render_exr(dir + "/c.exr", r);
  const lucent::RenderResult back = lucent::read_render(dir + "/c.exr");
  ASSERT_TRUE(back.light_mean_variance.has_value());
  EXPECT_EQ(back.light_mean_variance->paths[2], 1e-7);
  EXPECT_EQ(back.light_mean_variance->pixels[0], 0.125);
  std::setlocale(LC_ALL, before.c_str());
  EXPECT_EQ(lucent::read_render(dir + "/c.exr").light_mean_variance->paths[0], 0.5);
}

TEST(Parts, PartFilesKeepAndCheckTheirSums) {
  const std::string dir = lucent::test::temp_dir();
  const lucent::RenderPart part = noisy_part(dir, 64, 48, 4);
  for (lucent::PartCompression c : kCompressions) {
    SCOPED_TRACE(name_of(c));
    const std::string path = dir + "/p.exr";
    lucent::write_render_part(path, part, c);
    const lucent::RenderPart back = lucent::read_render_part(path);
    EXPECT_TRUE(bit_equal(back.acc.sum, part.acc.sum));
    EXPECT_TRUE(bit_equal(back.acc.sumsq, part.acc.sumsq));
    EXPECT_EQ(back.acc.count, part.acc.count);

    // the checksum of other sums
    const std::string bytes = lucent::test::read_file(path);
    const size_t at = bytes.find(std::string("lucent.checksum\0string\0", 23));
    ASSERT_NE(at, std::string::npos);
    std::string other = bytes;
    char& digit = other[at + 23 + 4];  // (after the value's 4-byte size)
    digit = digit == '0' ? '1' : '0';
    lucent::test::write_file(path, other);
    EXPECT_EQ(error_of([&] { lucent::read_render_part(path); }),
              path + ": part file is damaged: its samples do not match its checksum");

    // one byte of the pixel data changed, at 40 places in the file's second half: refused, or
    // the same sums (a byte that decodes the same). The image compare reads (read_render) too:
    // it was read from the display channels, which no checksum covers, and a damaged chunk of
    // them gave a mean of 1.5e24 without a word; it is now read from the checked sums.
    const lucent::RenderResult image = lucent::part_result(part);
    int refused = 0, same = 0;
    for (size_t k = bytes.size() / 2; k < bytes.size(); k += bytes.size() / 80) {
      std::string damaged = bytes;
      damaged[k] = static_cast<char>(damaged[k] ^ 0x5a);
      lucent::test::write_file(path, damaged);
      try {
        const lucent::RenderPart r = lucent::read_render_part(path);
        EXPECT_TRUE(bit_equal(r.acc.sum, part.acc.sum) && bit_equal(r.acc.sumsq, part.acc.sumsq) &&
                    r.acc.count == part.acc.count)
            << "byte " << k << ": other sums read without an error";
        ++same;
      } catch (const lucent::Error& e) {
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        ++refused;
      }
      try {
        const lucent::RenderResult r = lucent::read_render(path);
        EXPECT_TRUE(r.mean.rgb == image.mean.rgb && r.variance.rgb == image.variance.rgb &&
                    r.samples == image.samples)
            << "byte " << k << ": another image read without an error";
      } catch (const lucent::Error& e) {
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      }
    }
    EXPECT_GT(refused, 0);
  }
}

TEST(Parts, DamagedPartFilesAreOneLineErrors) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string good = dir + "/good.exr";
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples 0:4 -o " + q(good)).status, 0);
  const std::string bytes = lucent::test::read_file(good);
  const std::string out = dir + "/out.exr";
  ASSERT_EQ(run_cli("merge " + q(good) + " -o " + q(out)).status, 0) << "the good part merges";
  fs::remove(out);
  // the value of a string attribute: its name, NUL, "string", NUL, a 4-byte size, the value
  auto value_at = [&](const std::string& name) {
    const size_t at = bytes.find(name + std::string("\0string\0", 8));
    EXPECT_NE(at, std::string::npos) << name;
    return at + name.size() + 8 + 4;
  };
  const size_t hash = value_at("lucent.hash");
  const std::string hash_value = bytes.substr(hash, 16);
  // the display settings in the fewest digits that read back (gamma 2.2 was 2.2000000000000002)
  const size_t display = value_at("lucent.display");
  EXPECT_EQ(bytes.substr(display - 4, 20), std::string("\x10\0\0\0srgb,2.2,0,clamp", 20));
  struct Damage {
    std::string attribute, from, to, message;
  };
  const Damage damages[] = {
      {"lucent.format", "lucent-part 1", "lucent-part 9",
       "unsupported part format 'lucent-part 9' (expected 'lucent-part 1')"},
      {"lucent.film", "12x10", "12x11",
       "attribute lucent.film '12x11' differs from the image's 12x10"},
      {"lucent.hash", hash_value, "Z" + hash_value.substr(1),
       "attribute lucent.hash: invalid hash 'Z" + hash_value.substr(1) + "'"},
      {"lucent.samples", "0:4", "0:5",
       "attribute lucent.samples: [0, 5) lies outside the requested [0, 4)"},
      {"lucent.samples", "0:4", "4:0",
       "attribute lucent.samples: ranges must be non-empty, sorted and disjoint"},
      {"lucent.requested", "0:4", "0-4", "attribute lucent.requested: '0-4' is not a range A:B"},
      {"lucent.display", "srgb,", "srgx,", "attribute lucent.display: unknown transfer 'srgx'"},
      {"lucent.display", ",clamp", ",clamq", "attribute lucent.display: unknown tone map 'clamq'"},
      {"lucent.display", "srgb,", "srgb;", "attribute lucent.display: invalid 'srgb;"},
      // trailing characters (the scan stopped at them: 'clampX' read as clamp)
      {"lucent.display", "2,0,clamp", ",0,clampX", "attribute lucent.display: invalid 'srgb,"},
      {"lucent.seconds", "0.", "-.", "attribute lucent.seconds: negative time '-."},
      // names of no integrator or sampler (they were read as given)
      {"lucent.integrator", "path", "patz",
       "attribute lucent.integrator: unknown integrator 'patz'"},
      {"lucent.sampler", "sobol", "sobox", "attribute lucent.sampler: unknown sampler 'sobox'"},
  };
  int n = 0;
  for (const Damage& d : damages) {
    const size_t at = bytes.find(d.from, value_at(d.attribute));
    ASSERT_LT(at - value_at(d.attribute), 40u) << d.from << " is not in " << d.attribute;
    std::string damaged = bytes;
    damaged.replace(at, d.from.size(), d.to);
    const std::string path = dir + "/damaged" + std::to_string(n++) + ".exr";
    lucent::test::write_file(path, damaged);
    const std::string line = error_line(run_cli("merge " + q(path) + " -o " + q(out)));
    EXPECT_EQ(line.rfind(path + ": " + d.message, 0), 0u) << line;
    EXPECT_FALSE(fs::exists(out)) << d.message;
  }
  lucent::test::write_file(dir + "/text.exr", "not an image\n");
  EXPECT_EQ(error_line(run_cli("merge " + q(dir + "/text.exr") + " -o " + q(out))),
            dir + "/text.exr: not an OpenEXR file");
  EXPECT_FALSE(fs::exists(out));
  try {
    lucent::read_render_part(dir + "/text.exr");
    ADD_FAILURE() << "read a text file as a part";
  } catch (const lucent::Error& e) {
    EXPECT_EQ(std::string(e.what()),
              dir + "/text.exr: not a lucent part file (not an OpenEXR file)");
  }
}

// A part file's display channels (R, G, B) are not covered by its checksum; its sums are.
// read_image read the display channels: a checkpoint whose PIZ chunk was damaged there read as a
// changed image without a word, where read_render and compare read the sums. read_image of a
// part now gives the sums' image too. (The damaged file: the part's channels and attributes
// written again with its R channel changed.)
TEST(Parts, ReadImageOfAPartIsItsSumsImage) {
  const std::string dir = lucent::test::temp_dir();
  lucent::Renderer renderer(lucent::test::session_options());
  renderer.set_scene(lucent::load_scene(noisy_scene(dir)));
  const lucent::RenderPart part = render_range(renderer, 0, 4);
  const std::string good = dir + "/good.exr", bad = dir + "/bad.exr";
  lucent::write_render_part(good, part);
  const lucent::Image sums_image = lucent::read_render(good).mean;
  EXPECT_EQ(lucent::read_image(good).rgb, sums_image.rgb);

  const std::string bytes = lucent::test::read_file(good);
  lucent::image_detail::ExrChannels exr = lucent::image_detail::read_exr_channels(
      reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), good,
      lucent::image_detail::kMaxImagePixels);
  const int r = exr.find("R");
  ASSERT_GE(r, 0);
  for (float& v : exr.planes[size_t(r)]) v = 1.5e24f;  // the damage
  lucent::image_detail::RenderPlanes planes;
  planes.width = exr.width;
  planes.height = exr.height;
  const char* rgb[3] = {"R", "G", "B"};
  const char* var[3] = {"var.R", "var.G", "var.B"};
  for (int c = 0; c < 3; ++c) {
    planes.mean[c] = exr.planes[size_t(exr.find(rgb[c]))].data();
    planes.variance[c] = exr.planes[size_t(exr.find(var[c]))].data();
  }
  planes.samples = exr.uint_planes[size_t(exr.find("n"))].data();
  lucent::image_detail::ExrExtras extras;
  for (size_t i = 0; i < exr.names.size(); ++i)
    if (!exr.uint_planes[i].empty() && exr.names[i] != "n")
      extras.uint_channels.emplace_back(exr.names[i], exr.uint_planes[i].data());
  for (const auto& [name, value] : exr.attributes) extras.attributes.emplace_back(name, value);
  lucent::image_detail::write_render_planes(bad, planes, extras);
  ASSERT_EQ(lucent::read_render_part(bad).acc.sum, part.acc.sum);  // the sums are intact
  EXPECT_EQ(lucent::read_image(bad).rgb, sums_image.rgb);
}

// A part's counts agree with its header: each pixel holds the part's samples (the total of its
// ranges) less its non-finite ones, and those add up to lucent.nonfinite. Reading checked only that
// no count exceeded the samples: a part whose counts, ranges or non-finite count were altered
// merged into an image claiming samples it did not have (a part of [0, 6) holding 4 samples a
// pixel merged as 6 spp). Each damaged part is the good one altered and written again.
TEST(Parts, CountsDisagreeingWithTheHeaderAreOneLineErrors) {
  const std::string dir = lucent::test::temp_dir();
  lucent::Renderer renderer(lucent::test::session_options());
  renderer.set_scene(lucent::load_scene(noisy_scene(dir)));
  const lucent::RenderPart good = render_range(renderer, 0, 4);
  ASSERT_EQ(good.info.nonfinite, 0u);
  lucent::write_render_part(dir + "/good.exr", good);
  EXPECT_EQ(lucent::read_render_part(dir + "/good.exr").acc.count, good.acc.count);
  const std::string out = dir + "/out.exr";
  const size_t px = 3 * 12 + 5;  // pixel 5, 3
  struct Damage {
    std::function<void(lucent::RenderPart&)> alter;
    std::string message;
  };
  const Damage damages[] = {
      {[&](lucent::RenderPart& p) { p.acc.count[px] = 3; },
       "channel n: pixel 5, 3 counts 3 samples of the part's 4 (samples [0, 4)), and the part "
       "records no non-finite sample (lucent.nonfinite 0)"},
      {[&](lucent::RenderPart& p) { p.acc.count[px] = 5; },
       "channel n: pixel 5, 3 counts 5 samples, more than the part's 4 (samples [0, 4))"},
      {[](lucent::RenderPart& p) {
         p.info.samples = p.info.requested = {{0, 6}};
       },
       "channel n: pixel 0, 0 counts 4 samples of the part's 6 (samples [0, 6)), and the part "
       "records no non-finite sample (lucent.nonfinite 0)"},
      {[](lucent::RenderPart& p) { p.info.nonfinite = 7; },
       "attribute lucent.nonfinite: 7 non-finite samples recorded, but the pixels (channel n) "
       "miss 0 of the part's 4 (samples [0, 4)) per pixel"},
  };
  int n = 0;
  for (const Damage& d : damages) {
    lucent::RenderPart damaged = good;
    d.alter(damaged);
    const std::string path = dir + "/damaged" + std::to_string(n++) + ".exr";
    // the writer refuses it too, naming the same mismatch; the unchecked writer makes the file
    EXPECT_EQ(error_of([&] { lucent::write_render_part(path, damaged); }),
              path + ": cannot write part: " + d.message);
    EXPECT_FALSE(fs::exists(path));
    lucent::parts_detail::write_part_unchecked(path, damaged);
    EXPECT_EQ(error_of([&] { lucent::read_render_part(path); }), path + ": " + d.message);
    EXPECT_EQ(error_line(run_cli("merge " + q(path) + " -o " + q(out))), path + ": " + d.message);
    EXPECT_FALSE(fs::exists(out)) << d.message;
    // the merger checks parts it is handed in memory too (lucent-mpi's ranks)
    lucent::PartMerger merger;
    EXPECT_EQ(error_of([&] { merger.add("rank 1", damaged); }), "rank 1: " + d.message);
  }

  // a part with non-finite samples (a point light whose radiance squared overflows float) reads
  // and merges: its pixels miss exactly the samples it records as non-finite
  std::string text = lucent::test::read_file(noisy_scene(dir));
  const std::string dim = R"("intensity": [20, 20, 20])";
  ASSERT_NE(text.find(dim), std::string::npos);
  text.replace(text.find(dim), dim.size(), R"("intensity": [1e20, 1e20, 1e20])");
  lucent::test::write_file(dir + "/hot.json", text);
  renderer.set_scene(lucent::load_scene(dir + "/hot.json"));
  const lucent::RenderPart hot = render_range(renderer, 0, 4);
  ASSERT_GT(hot.info.nonfinite, 0u);
  ASSERT_LT(hot.info.nonfinite, 4u * 120);
  lucent::write_render_part(dir + "/hot0.exr", hot);
  lucent::write_render_part(dir + "/hot1.exr", render_range(renderer, 4, 8));
  CommandResult r =
      run_cli("merge " + q(dir + "/hot0.exr") + " " + q(dir + "/hot1.exr") + " -o " + q(out));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("non-finite sample(s) (NaN or Inf, or a square beyond a float's range) "
                       "were dropped"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(lucent::read_render_part(out).info.samples, (std::vector<lucent::SampleRange>{{0, 8}}));
  // one sample fewer in a pixel: the pixels miss one more than the non-finite samples, which
  // shows at the last pixel missing any
  const auto& counts = hot.acc.count;
  const size_t full = std::find(counts.begin(), counts.end(), 4u) - counts.begin();
  const size_t short_one =
      std::find_if(counts.begin(), counts.end(), [](std::uint32_t c) { return c < 4; }) -
      counts.begin();
  ASSERT_LT(full, counts.size()) << "no pixel holds every sample";
  ASSERT_LT(short_one, counts.size());
  lucent::RenderPart fewer = hot;
  fewer.acc.count[full] -= 1;
  size_t last = 0;
  for (size_t i = 0; i < counts.size(); ++i)
    if (fewer.acc.count[i] < 4) last = i;
  const std::string nf = std::to_string(hot.info.nonfinite);
  lucent::parts_detail::write_part_unchecked(dir + "/fewer.exr", fewer);
  EXPECT_EQ(error_of([&] { lucent::read_render_part(dir + "/fewer.exr"); }),
            dir + "/fewer.exr: channel n: pixel " + std::to_string(last % 12) + ", " +
                std::to_string(last / 12) + " counts " + std::to_string(fewer.acc.count[last]) +
                " samples of the part's 4 (samples [0, 4)): the pixels up to it miss " +
                std::to_string(hot.info.nonfinite + 1) + " samples, more than the " + nf +
                " non-finite ones the part records (lucent.nonfinite)");
  // one sample more: fewer missing than recorded
  lucent::RenderPart more = hot;
  more.acc.count[short_one] += 1;
  lucent::parts_detail::write_part_unchecked(dir + "/more.exr", more);
  EXPECT_EQ(error_of([&] { lucent::read_render_part(dir + "/more.exr"); }),
            dir + "/more.exr: attribute lucent.nonfinite: " + nf +
                " non-finite samples recorded, but the pixels (channel n) miss " +
                std::to_string(hot.info.nonfinite - 1) +
                " of the part's 4 (samples [0, 4)) per pixel");
}

// Sums that no render makes, in a crafted part whose checksum matches: a mean past a float's range
// merged into an infinite PFM pixel without a word, two parts of 1e308 seconds each failed at the
// output's writer (the error named the output), and rays past 2^64 wrapped. Each is refused now,
// naming the part, before the merge changes.
TEST(Parts, SumsNoRenderMakesAreRefusedNamingThePart) {
  const std::string dir = lucent::test::temp_dir();
  auto part = [](std::uint64_t begin, double sum, double sumsq) {
    lucent::RenderPart p = handmade_part({{begin, begin + 4}}, {0, 8});
    p.acc.sum = {sum, 0.5, 0.5};
    p.acc.sumsq = {sumsq, 0.5, 0.5};
    return p;
  };
  const std::string beyond =
      "pixel 0, 0: its mean or sample variance is beyond a float's range (no render's is)";
  // a mean of 1e39 in 4 samples: refused by the writer, the merger and, in a file, the readers
  const lucent::RenderPart huge = part(0, 4e39, 4e78);
  EXPECT_EQ(error_of([&] { lucent::write_render_part(dir + "/w.exr", huge); }),
            dir + "/w.exr: cannot write part: " + beyond);
  lucent::parts_detail::write_part_unchecked(dir + "/huge.exr", huge);
  EXPECT_EQ(error_line(run_cli("merge " + q(dir + "/huge.exr") + " -o " + q(dir + "/o.pfm"))),
            dir + "/huge.exr: " + beyond);
  EXPECT_FALSE(fs::exists(dir + "/o.pfm"));
  EXPECT_EQ(error_of([&] { lucent::read_render(dir + "/huge.exr"); }),
            dir + "/huge.exr: " + beyond);
  EXPECT_EQ(error_of([&] { lucent::read_render_part(dir + "/huge.exr"); }),
            dir + "/huge.exr: " + beyond);
  // each part fits (a mean of m = 3e38, then of 0; variances 0), their merge does not: its
  // variance is 2 m^2 / 7
  const double m = 3e38;
  lucent::PartMerger merger;
  merger.add("a", part(0, 4 * m, 4 * m * m));
  EXPECT_EQ(error_of([&] { merger.add("b", part(4, 0, 0)); }),
            "b: pixel 0, 0: merged with the parts before it, its mean or sample variance is beyond "
            "a float's range (no render's is)");
  // times and rays
  lucent::RenderPart a = part(0, 2, 1), b = part(4, 2, 1);
  a.info.seconds = b.info.seconds = 1e308;
  lucent::PartMerger times;
  times.add("a", a);
  EXPECT_EQ(error_of([&] { times.add("b", b); }),
            "b: attribute lucent.seconds: the parts' times add up past a double's range");
  a = part(0, 2, 1);
  b = part(4, 2, 1);
  a.info.rays = b.info.rays = 1ull << 63;
  lucent::PartMerger rays;
  rays.add("a", a);
  EXPECT_EQ(error_of([&] { rays.add("b", b); }),
            "b: attribute lucent.rays: the parts' rays add up past 2^64");
  b.info.rays -= 1;  // 2^64 - 1 in all
  rays.add("b", b);
  EXPECT_EQ(rays.finish().merged.info.rays, ~std::uint64_t(0));
}

// A part stopped by SIGTERM (Slurm's signal at a job's time limit) keeps the samples it finished,
// says which, and merges with a part of the range it left.
TEST(Parts, SigtermedPartRecordsItsRangeAndMerges) {
  std::string dir = lucent::test::temp_dir();
  std::string scene = noisy_scene(dir);
  std::string part = dir + "/long.exr", err = dir + "/long.err";
  // started in the background; SIGTERM once the progress line shows the render loop running
  // (from its first pass)
  std::string script = std::string(lucent::test::kEarlyProgress) + " '" +
                       std::string(LUCENT_CLI_PATH) + "' render " + q(scene) +
                       " --samples 0:16000000 -o " + q(part) + " 2>" + q(err) +
                       " </dev/null & pid=$!; for i in $(seq 600); do grep -q Msamples/s " +
                       q(err) + " && break; sleep 0.1; done; kill -TERM $pid; wait $pid";
  int raw = std::system(("bash -c " + q(script)).c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  std::string text = lucent::test::read_file(err);
  ASSERT_EQ(WEXITSTATUS(raw), 143) << text;
  lucent::PartInfo info = lucent::read_part_info(part);
  ASSERT_EQ(info.samples.size(), 1u) << text;
  const std::uint64_t k = info.samples[0].end;
  EXPECT_EQ(info.samples[0].begin, 0u);
  EXPECT_GT(k, 0u);
  EXPECT_LT(k, 16000000u);
  EXPECT_EQ(info.requested, (std::vector<lucent::SampleRange>{{0, 16000000}}));
  EXPECT_NE(text.find("lucent: " + part + " holds samples [0, " + std::to_string(k) +
                      ") of [0, 16000000)"),
            std::string::npos)
      << text;
  // the rest of the range, in part: the merge says what is still missing
  std::string rest = dir + "/rest.exr", out = dir + "/merged.exr";
  const std::string range = std::to_string(k) + ":" + std::to_string(k + 5);
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples " + range + " -o " + q(rest)).status, 0);
  CommandResult r = run_cli("merge " + q(part) + " " + q(rest) + " -o " + q(out));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(
      r.err.find("lucent: warning: samples [" + std::to_string(k + 5) + ", 16000000) are missing"),
      std::string::npos)
      << r.err;
  lucent::RenderPart merged = lucent::read_render_part(out);
  EXPECT_EQ(merged.info.samples, (std::vector<lucent::SampleRange>{{0, k + 5}}));
  EXPECT_EQ(*std::min_element(merged.acc.count.begin(), merged.acc.count.end()), k + 5);
}

// scripts/slurm: submit.sh submits the array of render-part.sbatch tasks and the merge.sbatch
// that depends on them; here tests/slurm/sbatch stands in for Slurm and runs them in order.
TEST(Parts, SlurmArrayScriptsRenderAndMerge) {
  std::string dir = lucent::test::temp_dir();
  std::string scene = noisy_scene(dir);
  const std::string out = dir + "/merged.exr", log = dir + "/jobs.log";
  const std::string cmd = "PATH=" + q(lucent::test::source_path("tests/slurm")) +
                          ":\"$PATH\" LUCENT=" + q(LUCENT_CLI_PATH) + " FAKE_SBATCH_LOG=" + q(log) +
                          " bash " + q(lucent::test::source_path("scripts/slurm/submit.sh")) + " " +
                          q(scene) + " 8 3 " + q(dir + "/parts") + " " + q(out) + " -q >" +
                          q(dir + "/submit.out") + " 2>" + q(dir + "/submit.err");
  int raw = std::system(cmd.c_str());
  const std::string err = lucent::test::read_file(dir + "/submit.err");
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << err;
  EXPECT_NE(lucent::test::read_file(dir + "/submit.out").find("(3 tasks), merge job"),
            std::string::npos);
  // three tasks of [0, 2), [2, 5), [5, 8), then the merge, all successful
  const std::string jobs = lucent::test::read_file(log);
  EXPECT_EQ(lucent::test::count_lines(jobs), 4) << jobs;
  size_t ok = 0;
  for (size_t at = jobs.find(": exit 0\n"); at != std::string::npos;
       at = jobs.find(": exit 0\n", at + 1))
    ++ok;
  EXPECT_EQ(ok, 4u) << jobs;
  EXPECT_EQ(lucent::read_part_info(dir + "/parts/part-0001.exr").samples,
            (std::vector<lucent::SampleRange>{{2, 5}}));
  EXPECT_NE(err.find("samples [0, 8)"), std::string::npos) << err;
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples 0:8 -o " + q(dir + "/one.exr")).status,
            0);
  lucent::RenderPart merged = lucent::read_render_part(out);
  EXPECT_EQ(merged.info.samples, (std::vector<lucent::SampleRange>{{0, 8}}));
  EXPECT_LT(max_relative_difference(merged.acc, lucent::read_render_part(dir + "/one.exr").acc),
            1e-5);
  // the merge's own options, LUCENT_MERGE_OPTS (submit.sh had no way to pass --complete): a task
  // that fails (a lucent that fails on task 1's samples) leaves samples [2, 5) missing, which
  // --complete makes the merge's error, writing nothing
  {
    const std::string failing = dir + "/failing-lucent";
    lucent::test::write_file(failing,
                             "#!/bin/sh\ncase \"$*\" in *'--samples 2:5'*) exit 1;; esac\n"
                             "exec '" +
                                 std::string(LUCENT_CLI_PATH) + "' \"$@\"\n");
    fs::permissions(failing, fs::perms::owner_all);
    std::string complete = "LUCENT_MERGE_OPTS=--complete " + cmd;
    complete.replace(complete.find("LUCENT=" + q(LUCENT_CLI_PATH)),
                     ("LUCENT=" + q(LUCENT_CLI_PATH)).size(), "LUCENT=" + q(failing));
    complete.replace(complete.find(q(dir + "/parts")), q(dir + "/parts").size(),
                     q(dir + "/parts2"));
    complete.replace(complete.find(q(out)), q(out).size(), q(dir + "/complete.exr"));
    std::remove(log.c_str());
    ASSERT_EQ(std::system(complete.c_str()), 0);
    const std::string e = lucent::test::read_file(dir + "/submit.err");
    EXPECT_NE(e.find("samples [2, 5) are missing"), std::string::npos) << e;
    // the task's failure and the merge's (the task's alone was there before)
    const std::string jobs2 = lucent::test::read_file(log);
    int failed = 0;
    for (size_t at = jobs2.find(": exit 1\n"); at != std::string::npos;
         at = jobs2.find(": exit 1\n", at + 1))
      ++failed;
    EXPECT_EQ(failed, 2) << jobs2;
    EXPECT_FALSE(fs::exists(dir + "/complete.exr"));
  }

  // one task again (sbatch --array=1): with the job's task count it renders its own range into
  // its own file; without it the one-task array is refused (it took itself for a whole job of
  // one task and wrote every sample over part 0)
  const std::string part0 = lucent::test::read_file(dir + "/parts/part-0000.exr");
  auto rerun = [&](const std::string& env, const std::string& spp = "8") {
    const std::string log1 = dir + "/rerun.log";
    std::remove(log1.c_str());
    const std::string c = env + " PATH=" + q(lucent::test::source_path("tests/slurm")) +
                          ":\"$PATH\" LUCENT=" + q(LUCENT_CLI_PATH) +
                          " FAKE_SBATCH_LOG=" + q(log1) + " sbatch --array=1 " +
                          q(lucent::test::source_path("scripts/slurm/render-part.sbatch")) + " " +
                          q(scene) + " " + spp + " " + q(dir + "/parts") + " -q >/dev/null 2>" +
                          q(dir + "/rerun.err");
    EXPECT_EQ(std::system(c.c_str()), 0);
    return lucent::test::read_file(log1);
  };
  EXPECT_NE(rerun("").find("_1: exit 2"), std::string::npos);
  EXPECT_NE(lucent::test::read_file(dir + "/rerun.err").find("set LUCENT_TASKS"),
            std::string::npos);
  EXPECT_EQ(lucent::test::read_file(dir + "/parts/part-0000.exr"), part0);
  EXPECT_NE(rerun("LUCENT_TASKS=3").find("_1: exit 0"), std::string::npos);
  EXPECT_EQ(lucent::read_part_info(dir + "/parts/part-0001.exr").samples,
            (std::vector<lucent::SampleRange>{{2, 5}}));
  EXPECT_EQ(lucent::test::read_file(dir + "/parts/part-0000.exr"), part0);

  // an SPP with a leading zero: refused (bash read 010 as octal 8, and the tasks split 8 of the
  // 10 samples, every job succeeding), by the task and before anything is queued
  EXPECT_NE(rerun("LUCENT_TASKS=3", "010").find("_1: exit 2"), std::string::npos);
  EXPECT_NE(lucent::test::read_file(dir + "/rerun.err").find("SPP must be"), std::string::npos);
  std::string bad = cmd;
  bad.replace(bad.find(" 8 3 "), 5, " 010 3 ");
  raw = std::system(bad.c_str());
  EXPECT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 2);
  EXPECT_EQ(lucent::test::read_file(dir + "/submit.err"),
            "submit: SPP must be a number of at least the 3 tasks and at most 4294967296 (no "
            "leading zero), got '010'\n");
  // an SPP that every task would fail on (a share past a part's 2^24 samples), or past 2^32, or
  // too long for bash's arithmetic (it wrapped, and the tasks got negative ranges): refused
  // before anything is queued (the jobs were queued and all failed)
  const std::pair<const char*, const char*> refused[] = {
      {" 40000000 2 ",
       "submit: 40000000 samples in 2 tasks give a task more than the 16777216 samples a part "
       "holds: use at least 3 tasks\n"},
      {" 4294967297 300 ",
       "submit: SPP must be a number of at least the 300 tasks and at most 4294967296 (no "
       "leading zero), got '4294967297'\n"},
      {" 99999999999999999999 3 ",
       "submit: SPP must be a number of at least the 3 tasks and at most 4294967296 (no "
       "leading zero), got '99999999999999999999'\n"},
      {" 8 99999999999999999999 ",
       "submit: TASKS must be a number from 1 to 4000001, got '99999999999999999999'\n"}};
  for (const auto& [args, message] : refused) {
    std::string c = cmd;
    c.replace(c.find(" 8 3 "), 5, args);
    raw = std::system(c.c_str());
    EXPECT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 2) << args;
    EXPECT_EQ(lucent::test::read_file(dir + "/submit.err"), message);
  }
}

#ifdef LUCENT_MPI_PATH
/// How long mpirun leaves the other ranks once one has exited with a non-zero status or been
/// signalled (odls_base_sigkill_timeout).
enum class Grace {
  /// none: the job's ranks exit together (lucent-mpi's ranks agree on their status and finalize
  /// before they exit), and mpirun's default would only add 2 s (a second before SIGTERM, one
  /// before SIGKILL) to every run that exits non-zero
  none,
  /// mpirun's default second: what the ranks have to stop, write and finalize when mpirun
  /// itself is signalled (it passes the signal on, then kills them). A test that signals the
  /// ranks needs none: they agree on the stop and finalize together (Open MPI's MPI_Finalize
  /// fences the ranks by default; the MPI standard does not promise it), so the first to exit
  /// leaves nothing to write
  mpirun_default,
};

/// The Open MPI settings of every job a test starts (variable assignments, each followed by a
/// space): root allowed (containers), no CMA single copy (ptrace is often restricted in
/// containers), and the ob1 point-to-point layer, the one Open MPI selects on one node without a
/// fabric: naming it spares each process's MPI_Init opening the cm layer, whose PSM libraries
/// take 0.2 s of its 0.3 s here, a wait rather than CPU (every lucent-mpi process of these tests
/// paid it; `mpirun -np 2` of MPI_Init and MPI_Finalize alone: 0.5 s -> 0.3 s).
const char* const kOmpiSettings =
    "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
    "OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_pml=ob1 ";

/// mpirun with the settings a test needs (kOmpiSettings), oversubscription of the 2-core
/// machine.
std::string mpirun(const std::string& args, Grace grace = Grace::none) {
  return std::string(kOmpiSettings) +
         (grace == Grace::none ? "OMPI_MCA_odls_base_sigkill_timeout=0 " : "") + "'" +
         LUCENT_MPIEXEC + "' --oversubscribe " + args;
}

bool have_mpirun() { return fs::exists(LUCENT_MPIEXEC); }

CommandResult run_shell(const std::string& cmd, const std::string& dir) {
  int raw =
      std::system((cmd + " </dev/null >" + q(dir + "/out") + " 2>" + q(dir + "/err")).c_str());
  CommandResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  r.out = lucent::test::read_file(dir + "/out");
  r.err = lucent::test::read_file(dir + "/err");
  return r;
}

/// run_shell of each of `cmds` at the same time (in `dir`, each with its own output files), for
/// commands independent of each other: an MPI process spends most of its start and end waiting
/// (0.5 s of wall time for 0.1 s of CPU here), so a test of many short ones waits once instead
/// of once each.
std::vector<CommandResult> run_shells_together(const std::vector<std::string>& cmds,
                                               const std::string& dir) {
  std::string script;
  for (size_t i = 0; i < cmds.size(); ++i) {
    const std::string base = dir + "/together" + std::to_string(i);
    script += "(" + cmds[i] + " </dev/null >" + q(base + ".out") + " 2>" + q(base + ".err") +
              "; echo $? >" + q(base + ".status") + ") &\n";
  }
  script += "wait\n";
  lucent::test::write_file(dir + "/together.sh", script);
  const int raw = std::system(("bash " + q(dir + "/together.sh")).c_str());
  EXPECT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << raw;
  std::vector<CommandResult> results(cmds.size());
  for (size_t i = 0; i < cmds.size(); ++i) {
    const std::string base = dir + "/together" + std::to_string(i);
    const std::string status = lucent::test::read_file(base + ".status");
    results[i].status = status.empty() ? -1 : std::atoi(status.c_str());
    results[i].out = lucent::test::read_file(base + ".out");
    results[i].err = lucent::test::read_file(base + ".err");
  }
  return results;
}

TEST(Parts, MpiTwoRanksRenderTheOneProcessImage) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  std::string dir = lucent::test::temp_dir();
  std::string scene = noisy_scene(dir);
  CommandResult r = run_shell(mpirun("-np 2 '" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) +
                                     " --spp 8 -o " + q(dir + "/mpi.exr")),
                              dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("samples [0, 8) from 2 ranks"), std::string::npos) << r.err;
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples 0:8 -o " + q(dir + "/one.exr")).status,
            0);
  lucent::RenderPart mpi = lucent::read_render_part(dir + "/mpi.exr");
  lucent::RenderPart one = lucent::read_render_part(dir + "/one.exr");
  EXPECT_EQ(mpi.info.scene_hash, one.info.scene_hash);
  EXPECT_EQ(mpi.info.samples, (std::vector<lucent::SampleRange>{{0, 8}}));
  EXPECT_LT(max_relative_difference(mpi.acc, one.acc), 1e-5);
}

// Rank 0's progress line starts after a second of rendering; under LUCENT_TEST_EARLY_PROGRESS=1
// (the stop-signal tests' sign that every rank renders, kEarlyProgress) once every rank has
// rendered a pass: here within a render of half a second.
TEST(Parts, MpiProgressLineOnceEveryRankRendersForTheStopSignalTests) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  std::string dir = lucent::test::temp_dir();
  std::string scene = noisy_scene(dir);
  CommandResult r =
      run_shell(std::string(lucent::test::kEarlyProgress) + " " +
                    mpirun("-np 2 '" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) +
                           " --spp 16000000 --time 0.5 -o " + q(dir + "/mpi.exr")),
                dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::regex_search(r.err, std::regex("(^|\n)rank 0 of 2: +[0-9.]+%  [0-9]+ of "
                                                  "8000000 spp  [0-9.]+ Msamples/s\n")))
      << r.err;
}

// Rank 0 merges the parts and writes the image after every rank has rendered: a write the
// host's memory cannot hold (a 2048x2048 part file, under an address-space limit the session
// fits) is refused before rendering, naming the write, instead of failing after the job's work.
TEST(Parts, MpiOutputTooLargeToWriteIsRefusedBeforeRendering) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  if (lucent::test::kAddressSanitizer)
    GTEST_SKIP() << "AddressSanitizer cannot run under ulimit -v";
  std::string dir = lucent::test::temp_dir();
  std::string scene = noisy_scene(dir);
  const std::string out = dir + "/mpi.exr";
  CommandResult r =
      run_shell("ulimit -v 1500000; timeout 60 env " +
                    mpirun("-np 1 '" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) +
                           " --width 2048 --height 2048 --spp 1 -o " + q(out)),
                dir);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("lucent-mpi: error: rank 0 of 1 ("), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the largest part is writing "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("mpi.exr (2048x2048) (906.5 MiB): reduce the film size"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Parts, MpiFailingRankEndsTheJobWithoutOutput) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  // (the slowest of the MPI entries, 6-12 s each under the sanitizers: the release build runs
  // them; the sanitizer build runs the other lucent-mpi entries, which take the same paths)
  if (lucent::test::kAddressSanitizer) GTEST_SKIP() << "slow under AddressSanitizer";
  std::string dir = lucent::test::temp_dir();
  std::string scene = noisy_scene(dir);
  const std::string out = dir + "/mpi.exr";
  const std::string prog = "'" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) + " -o " + q(out);
  // rank 1 asks for a device this machine does not have
  CommandResult r =
      run_shell(mpirun("-np 1 " + prog + " : -np 1 -x LUCENT_DEVICE=no-such-device " + prog), dir);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("lucent-mpi: error: rank 1 of 2 ("), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no-such-device"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // every rank without its device: one line, the lowest rank's (each rank printed its own)
  r = run_shell(mpirun("-np 2 -x LUCENT_DEVICE=no-such-device " + prog), dir);
  EXPECT_EQ(r.status, 1) << r.err;
  // (mpirun adds its own report of the exit status)
  size_t lines = 0;
  for (size_t at = r.err.find("lucent-mpi:"); at != std::string::npos;
       at = r.err.find("lucent-mpi:", at + 1))
    ++lines;
  EXPECT_EQ(lines, 1u) << r.err;
  EXPECT_EQ(r.err.rfind("lucent-mpi: error: rank 0 of 2 (", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(out));
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find("mpi.exr"), std::string::npos)
        << "a temporary output was left: " << entry.path();

  // ranks given other arguments (mpirun's A : B): one that cannot parse them, where rank 0 hung
  // waiting for its part; one of another --spp, whose share left a gap in an image written
  // with exit 0
  r = run_shell("timeout 60 env " + mpirun("-np 1 " + prog + " : -np 1 " + prog + " --bogus"), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("lucent-mpi: error: rank 1 of 2: The following argument was not expected: "
                       "--bogus (its arguments are not rank 0's)"),
            std::string::npos)
      << r.err;
  // --help on a rank other than 0: CLI11's "This should be caught in your main function"
  r = run_shell("timeout 60 env " + mpirun("-np 1 " + prog + " : -np 1 " + prog + " --help"), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("lucent-mpi: error: rank 1 of 2: --help or --version is for rank 0 alone "
                       "(its arguments are not rank 0's)"),
            std::string::npos)
      << r.err;
  // (refused before rendering, as a rank of another seed, precision or scene: each rendered its
  // whole share, hours on a cluster, before rank 0 refused its part; here a render of 1.6e7 spp
  // would outlast the timeout)
  const std::pair<std::string, std::string> differ[] = {
      {" --spp 8 : -np 1 " + prog + " --spp 100",
       "rank 1 is given samples [50, 100), its share of rank 0's is [4, 8) (another --spp?)"},
      {" --spp 16000000 : -np 1 " + prog + " --spp 16000000 --seed 5",
       "rank 1: seed 5 differs from rank 0's 3"},
      {" --spp 16000000 : -np 1 " + prog + " --spp 16000000 --precision double",
       "rank 1: scene hash "}};
  for (const auto& [args, says] : differ) {
    r = run_shell("timeout 60 env " + mpirun("-np 1 " + prog + args), dir);
    EXPECT_EQ(r.status, 1) << args << "\n" << r.err;
    EXPECT_NE(r.err.find("lucent-mpi: error: rank 0 of 2 ("), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  // a rank that stops early (here by a time limit that rank 0 has not): the image is written,
  // and the exit status and the last line say that samples are missing
  r = run_shell(mpirun("-np 1 " + prog + " --spp 8 : -np 1 " + prog + " --spp 8 --time 1e-9"), dir);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("are missing (a rank stopped early)"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(out));
}
// A command line lucent-mpi cannot parse is one line and status 2, as for `lucent`: CLI11's own
// exit printed two lines and exited 105, 106 or 109, a --time of nan passed the parser and ended
// in a rank's MPI_Abort, and one of inf was refused naming 1.8e308 in 300 digits.
TEST(Parts, MpiCommandLineErrorsAreOneLine) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  std::string dir = lucent::test::temp_dir();
  std::string scene = noisy_scene(dir);
  const std::string out = dir + "/mpi.exr";
  // one process, without mpirun: MPI's singleton start (mpirun adds its own report of the status)
  const std::string prog =
      std::string("env ") + kOmpiSettings + "'" + std::string(LUCENT_MPI_PATH) + "' ";
  const std::pair<std::string, std::string> cases[] = {
      {q(scene) + " -o " + q(out) + " --time nan", "--time nan: must be a finite number"},
      {q(scene) + " -o " + q(out) + " --time inf", "--time inf: must be a finite number"},
      // reals are plain decimal (CLI11 took 0x10 as 16)
      {q(scene) + " -o " + q(out) + " --time 0x10", "--time 0x10: reals are decimal numbers"},
      {q(scene) + " -o " + q(out) + " --checkpoint-every ' 5'",
       "--checkpoint-every ' 5': reals are decimal numbers"},
      {q(scene) + " -o " + q(out) + " --time 2e7", "--time: must be in (0, 1e7] seconds, got 2e7"},
      {q(scene) + " -o " + q(out) + " --time -1", "--time: must be in (0, 1e7] seconds, got -1"},
      {q(scene) + " -o " + q(out) + " --bogus", "--bogus"},
      {q(scene) + " -o " + q(out) + " --spp 0", "--spp"},
      // integers are plain decimal (CLI11 read 010 as octal 8, 0b11 as binary)
      {q(scene) + " -o " + q(out) + " --spp 010",
       "--spp 010: integers are plain decimal digits, without a leading zero or a base prefix"},
      {q(scene) + " -o " + q(out) + " --width 0b11", "--width 0b11: integers are plain decimal"},
      // an empty --device fell back to LUCENT_DEVICE, an empty --checkpoint to none
      {q(scene) + " -o " + q(out) + " --device ''", "--device: must not be empty"},
      {q(scene) + " -o " + q(out) + " --checkpoint ''", "--checkpoint: must not be empty"},
      {q(scene) + " -o ''", "--output: must not be empty"},
      {"'' -o " + q(out), "scene: must not be empty"},
      {q(scene), "--output is required"}};
  // (all at once: each is a singleton start, a wait of about half a second)
  std::vector<std::string> commands;
  for (const auto& [args, says] : cases) commands.push_back("timeout 60 " + prog + args);
  commands.push_back("timeout 60 " + prog + "--help");
  const std::vector<CommandResult> results = run_shells_together(commands, dir);
  for (size_t i = 0; i < std::size(cases); ++i) {
    const auto& [args, says] = cases[i];
    const CommandResult& r = results[i];
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("lucent-mpi: error: ", 0), 0u) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << "\n" << r.err;
    EXPECT_NE(r.err.find("(see lucent-mpi --help)\n"), std::string::npos) << args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out)) << args;
  }
  // an empty POCL_CACHE_DIR, on which PoCL aborts in the singleton's daemon (orted probes the
  // OpenCL devices): refused before MPI_Init, one line (it was orted's assertion, then Open MPI's
  // reports of a failed MPI_Init)
  CommandResult cache = run_shell(
      "timeout 60 env POCL_CACHE_DIR= " + prog + q(scene) + " -o " + q(out) + " --spp 2", dir);
  EXPECT_EQ(cache.status, 1) << cache.err;
  EXPECT_EQ(cache.err,
            "lucent-mpi: error: POCL_CACHE_DIR is set but empty, which PoCL aborts on: unset it "
            "or name a directory\n");
  EXPECT_FALSE(fs::exists(out));
  // a thread count PoCL cannot read: it crashed in the singleton's daemon (SIGSEGV), then Open
  // MPI's reports
  cache = run_shell(
      "timeout 60 env POCL_MAX_PTHREAD_COUNT=-1 " + prog + q(scene) + " -o " + q(out) + " --spp 2",
      dir);
  EXPECT_EQ(cache.status, 1) << cache.err;
  EXPECT_EQ(cache.err.rfind("lucent-mpi: error: POCL_MAX_PTHREAD_COUNT", 0), 0u) << cache.err;
  EXPECT_EQ(std::count(cache.err.begin(), cache.err.end(), '\n'), 1) << cache.err;
  const CommandResult& help = results.back();
  EXPECT_EQ(help.status, 0) << help.err;
  EXPECT_NE(help.out.find("--time"), std::string::npos) << help.out;
  EXPECT_EQ(help.err, "");
  // a valid time still renders
  CommandResult ok =
      run_shell("timeout 60 " + prog + q(scene) + " -q --spp 2 --time 1e7 -o " + q(out), dir);
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_TRUE(fs::exists(out));
}

// lucent-mpi's output may not be a file the scene reads (an environment map here): rank 0 wrote
// over it, as `lucent render` refuses to.
TEST(Parts, MpiRefusesToOverwriteWhatTheSceneReads) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  std::string dir = lucent::test::temp_dir();
  const std::string env = dir + "/sky.pfm";
  lucent::Image sky{2, 1, std::vector<float>(6, 0.5f)};
  lucent::write_image(env, sky);
  const std::string before = lucent::test::read_file(env);
  const std::string scene = dir + "/scene.json";
  lucent::test::write_file(scene, R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 30},
    "film": {"width": 8, "height": 8},
    "integrator": {"type": "path", "max_depth": 2, "spp": 2},
    "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}],
    "lights": [{"type": "environment", "file": "sky.pfm"}]})");
  CommandResult r = run_shell(
      mpirun("-np 2 '" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) + " -o " + q(env)), dir);
  // refused by rank 0 alone, agreed by the ranks: one line and status 1
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err.rfind("lucent-mpi: error: rank 0 of 2 (", 0), 0u) << r.err;
  EXPECT_EQ(r.err.find("MPI_ABORT"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(": is an input of this render ("), std::string::npos) << r.err;
  EXPECT_EQ(lucent::test::read_file(env), before);
}
// Slurm (and a user's Ctrl-C) signal mpirun, not the ranks: Open MPI's mpirun passes SIGTERM on
// to them, and they stop after their pass, send what they rendered, and rank 0 writes it with its
// ranges, before mpirun's own time to kill them runs out.
TEST(Parts, MpiSigtermToMpirunWritesWhatTheRanksRendered) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  std::string dir = lucent::test::temp_dir();
  std::string scene = noisy_scene(dir);
  const std::string out = dir + "/mpi.exr", err = dir + "/mpi.err";
  // in the background; SIGTERM to mpirun once rank 0's progress line shows that every rank has
  // rendered a pass
  const std::string script = dir + "/stop.sh";
  lucent::test::write_file(script, std::string(lucent::test::kEarlyProgress) + " " +
                                       mpirun("-np 2 '" + std::string(LUCENT_MPI_PATH) + "' " +
                                                  q(scene) + " --spp 16000000 -o " + q(out),
                                              Grace::mpirun_default) +
                                       " 2>" + q(err) +
                                       " </dev/null & pid=$!\nfor i in $(seq 600); do grep -q " +
                                       "'rank 0 of 2:' " + q(err) +
                                       " && break; sleep 0.1; done\nkill -TERM $pid\nwait $pid\n");
  int raw = std::system(("bash " + q(script)).c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  const std::string text = lucent::test::read_file(err);
  EXPECT_NE(WEXITSTATUS(raw), 0) << text;
  ASSERT_TRUE(fs::exists(out)) << text;
  lucent::PartInfo info = lucent::read_part_info(out);
  ASSERT_EQ(info.samples.size(), 2u) << text;
  EXPECT_EQ(info.samples[0].begin, 0u);
  EXPECT_EQ(info.samples[1].begin, 8000000u);
  EXPECT_GT(info.samples[0].end, 0u);
  EXPECT_LT(info.samples[0].end, 8000000u);
  EXPECT_GT(info.samples[1].end, 8000000u);
  EXPECT_LT(info.samples[1].end, 16000000u);
  EXPECT_NE(text.find("lucent-mpi: interrupted: " + out + " holds samples [0, "), std::string::npos)
      << text;
}

// scripts/slurm/mpi.sbatch: Slurm's SIGTERM to the batch shell (--signal=B:TERM) reaches the
// ranks, which write their checkpoints and the partial output (exec: mpirun is the shell; a bash
// that ran mpirun in the foreground died on it without passing it on, the ranks rendering on).
TEST(Parts, SlurmMpiScriptPassesTheStopToTheRanks) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  std::string dir = lucent::test::temp_dir();
  std::string scene = noisy_scene(dir);
  const std::string out = dir + "/mpi.exr", ck = dir + "/ck.exr", err = dir + "/mpi.err";
  const std::string script = dir + "/stop.sh";
  // (a grace of 2 s, not the script's 30)
  lucent::test::write_file(
      script,
      std::string(lucent::test::kEarlyProgress) + " " + kOmpiSettings +
          "OMPI_MCA_odls_base_sigkill_timeout=2 MPIRUN_ARGS='--oversubscribe -np 2' MPIRUN='" +
          std::string(LUCENT_MPIEXEC) + "' LUCENT_MPI='" + LUCENT_MPI_PATH + "' bash " +
          q(lucent::test::source_path("scripts/slurm/mpi.sbatch")) + " " + q(scene) + " " + q(out) +
          " " + q(ck) + " --spp 16000000 2>" + q(err) +
          " </dev/null & pid=$!\nfor i in $(seq 600); do grep -q 'rank 0 of 2:' " + q(err) +
          " && break; sleep 0.1; done\nkill -TERM $pid\nwait $pid\n");
  int raw = std::system(("timeout 120 bash " + q(script)).c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  const std::string text = lucent::test::read_file(err);
  EXPECT_NE(WEXITSTATUS(raw), 0) << text;
  ASSERT_TRUE(fs::exists(out)) << text;
  EXPECT_EQ(lucent::read_part_info(out).samples.size(), 2u) << text;
  for (int r = 0; r < 2; ++r) {
    const std::string rank = dir + "/ck.rank" + std::to_string(r) + "-of-2.exr";
    ASSERT_TRUE(fs::exists(rank)) << text;
    EXPECT_EQ(lucent::read_part_info(rank).samples.size(), 1u) << text;
  }
  EXPECT_NE(text.find("the same command with 2 ranks resumes the render"), std::string::npos)
      << text;
}

/// A pattern (pkill -f) of the command line of the lucent-mpi rank given `-q` last: it starts with
/// the program (mpirun's holds the rank's arguments too, but does not start with it) and holds
/// `scene` (in a directory of the test's own: no other test's ranks match).
std::string quiet_rank_pattern(const std::string& program, const std::string& scene) {
  const auto literal = [](const std::string& text) {  // (a regex matching `text` alone)
    std::string escaped;
    for (char c : text) {
      if (std::string("\\.+*?()[]{}|^$").find(c) != std::string::npos) escaped += '\\';
      escaped += c;
    }
    return escaped;
  };
  return "^" + literal(program) + " " + literal(scene) + " .* -q$";
}

// A stop signal to one rank alone (a node drained) is an interruption of the job, whether or not
// --time was given: under --time the image was written short with exit 0 and no word, its
// missing samples taken for the time limit's.
TEST(Parts, MpiSigtermToOneRankUnderATimeLimitIsAnInterruption) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  std::string dir = lucent::test::temp_dir();
  std::string scene = noisy_scene(dir);
  const std::string out = dir + "/mpi.exr", err = dir + "/mpi.err";
  const std::string prog =
      "'" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) + " --spp 16000000 -o " + q(out);
  // rank 0 stops at its time limit; rank 1, without one, only by the signal, whenever it comes
  const std::string script = dir + "/stop.sh";
  lucent::test::write_file(
      script, "timeout 120 env " + std::string(lucent::test::kEarlyProgress) + " " +
                  mpirun("-np 1 " + prog + " --time 3 : -np 1 " + prog + " -q") + " 2>" + q(err) +
                  " </dev/null & pid=$!\nfor i in $(seq 600); do grep -q 'rank 0 of 2:' " + q(err) +
                  " && break; sleep 0.1; done\npkill -TERM -f " +
                  q(quiet_rank_pattern(LUCENT_MPI_PATH, scene)) + "\nwait $pid\n");
  int raw = std::system(("bash " + q(script)).c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  const std::string text = lucent::test::read_file(err);
  EXPECT_EQ(WEXITSTATUS(raw), 143) << text;
  ASSERT_TRUE(fs::exists(out)) << text;
  EXPECT_NE(text.find("lucent-mpi: interrupted (a stop signal on rank 1 of 2): " + out +
                      " holds samples [0, "),
            std::string::npos)
      << text;
}

// A stop signal to one rank alone stops every rank within a few passes: the ranks agree on it
// while they render (lucent-mpi's StopAgreement), and each keeps what it rendered. They agreed
// only once each had ended its render, and the others rendered their whole share first (here
// 5.3 million samples per pixel each, hours: the job ran until `timeout` stopped all of it). Rank
// 2 ends its share early (--time 0.001: after its first pass) and waits for the others, in the
// agreement: a rank that has finished takes part until every rank has.
TEST(Parts, MpiSigtermToOneRankStopsEveryRankAfterTheirPass) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  std::string dir = lucent::test::temp_dir();
  std::string scene = noisy_scene(dir);
  const std::string out = dir + "/mpi.exr", err = dir + "/mpi.err";
  const std::uint64_t n = 16000000;
  const std::string prog = "'" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) + " --spp " +
                           std::to_string(n) + " -o " + q(out);
  // SIGTERM to rank 1 (given -q) once rank 0's progress line shows that every rank has rendered a
  // pass (rank 2 its last); `timeout` (status 124) ends a job whose ranks render on
  const std::string script = dir + "/stop.sh";
  lucent::test::write_file(
      script,
      "timeout 120 env " + std::string(lucent::test::kEarlyProgress) + " " +
          mpirun("-np 1 " + prog + " : -np 1 " + prog + " -q : -np 1 " + prog + " --time 0.001") +
          " 2>" + q(err) + " </dev/null & pid=$!\nfor i in $(seq 600); do grep -q 'rank 0 of 3:' " +
          q(err) + " && break; sleep 0.1; done\npkill -TERM -f " +
          q(quiet_rank_pattern(LUCENT_MPI_PATH, scene)) + "\nwait $pid\n");
  int raw = std::system(("bash " + q(script)).c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  const std::string text = lucent::test::read_file(err);
  EXPECT_EQ(WEXITSTATUS(raw), 143) << text;
  EXPECT_NE(text.find("lucent-mpi: interrupted (a stop signal on rank 1 of 3): " + out +
                      " holds samples [0, "),
            std::string::npos)
      << text;
  ASSERT_TRUE(fs::exists(out)) << text;
  // every rank rendered some of its share, and stopped short of it (rank 2 at its time limit)
  const lucent::PartInfo info = lucent::read_part_info(out);
  ASSERT_EQ(info.samples.size(), 3u) << text;
  for (std::uint64_t r = 0; r < 3; ++r) {
    const lucent::SampleRange share = {n * r / 3, n * (r + 1) / 3};
    EXPECT_EQ(info.samples[r].begin, share.begin) << r << "\n" << text;
    EXPECT_GT(info.samples[r].end, share.begin) << r << "\n" << text;
    EXPECT_LT(info.samples[r].end, share.end) << r << "\n" << text;
  }
}

/// The names in `dir` that contain `part`.
std::vector<std::string> names_with(const std::string& dir, const std::string& part) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.find(part) != std::string::npos) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

/// The lines of `err` that lucent-mpi printed (mpirun adds its own reports).
int lucent_mpi_lines(const std::string& err) {
  int n = 0;
  for (size_t at = 0; (at = err.find("lucent-mpi:", at)) != std::string::npos; ++at)
    n += at == 0 || err[at - 1] == '\n';
  return n;
}

// Every rank loads the scene and builds the session, and each printed the scene's warnings: a
// job of K ranks printed each K times. Rank 0 prints them once (the other ranks' own too, naming
// the rank), before the one line of a job that fails.
TEST(Parts, MpiWarningsArePrintedOnce) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  const std::string dir = lucent::test::temp_dir();
  std::string text = lucent::test::read_file(noisy_scene(dir));
  const std::string grey = "[0.25, 0.5, 0.75]";
  ASSERT_NE(text.find(grey), std::string::npos);
  text.replace(text.find(grey), grey.size(), "[1.25, 0.5, 0.75]");
  // (a tab in its name: rank 0 kept its own warning as given, the others sent it as one line,
  // "\t", and it was printed twice)
  const std::string scene = dir + "/bright\t.json";
  lucent::test::write_file(scene, text);
  auto count = [](const std::string& err) {
    int n = 0;
    for (size_t at = 0; (at = err.find("albedo 1.25 in red is above 1", at)) != std::string::npos;
         ++at)
      ++n;
    return n;
  };
  const std::string prog = "'" + std::string(LUCENT_MPI_PATH) + "' " + q(scene);
  CommandResult r =
      run_shell(mpirun("-np 3 " + prog + " --spp 6 -q -o " + q(dir + "/mpi.exr")), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(count(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("lucent: warning: " + dir + "/bright\\t.json: material 'm'", 0), 0u)
      << r.err;
  // a job that fails after the session's build (rank 0's checkpoint is of another seed): the
  // warning, then the failure's line
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --seed 9 --samples 0:2 -o " +
                    q(dir + "/ck.rank0-of-3.exr"))
                .status,
            0);
  r = run_shell(mpirun("-np 3 " + prog + " --spp 6 -q --checkpoint " + q(dir + "/ck.exr") + " -o " +
                       q(dir + "/mpi.exr")),
                dir);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(count(r.err), 1) << r.err;
  EXPECT_EQ(lucent_mpi_lines(r.err), 1) << r.err;
  EXPECT_LT(r.err.find("albedo 1.25"), r.err.find("lucent-mpi: error: rank 0 of 3")) << r.err;
}

// Errors before rendering are agreed by the ranks: one line naming the lowest failing rank,
// status 1, no output. A scene no rank can read (the commonest mistake), too many ranks for the
// samples and a kernel that does not build (an error injected into a copy of the kernel sources,
// LUCENT_KERNEL_DIR) printed one line per rank, then Open MPI's report of MPI_Abort (eight lines),
// and the build failure's line referred to a "build log above" that no rank printed.
TEST(Parts, MpiSceneErrorsAreOneLine) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir), out = dir + "/mpi.exr";
  const std::string kernels = lucent::test::kernel_copy();
  std::ofstream(kernels + "/megakernel.cl", std::ios::app) << "\nlucent_injected_error here;\n";
  const std::string prog = "'" + std::string(LUCENT_MPI_PATH) + "' ";
  // a scene with light-traced caustics (scenes/course.json): refused, and rendered with
  // --no-caustics (ranks could not render it without editing the file)
  std::string text = lucent::test::read_file(scene);
  const auto edit = [&text](const std::string& from, const std::string& to) {
    text.replace(text.find(from), from.size(), to);
  };
  edit("\"spp\": 8", "\"spp\": 8, \"caustics\": true");
  edit("\"materials\": {", "\"materials\": {\"glass\": {\"type\": \"dielectric\", \"ior\": 1.5}, ");
  edit("\"radius\": 0.5, \"material\": \"m\"", "\"radius\": 0.5, \"material\": \"glass\"");
  const std::string caustics = dir + "/caustics.json";
  lucent::test::write_file(caustics, text);
  CommandResult r =
      run_shell(mpirun("-np 2 " + prog + q(caustics) + " --no-caustics -o " + q(out)), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(out)) << r.err;
  fs::remove(out);
  const std::pair<std::string, std::string> cases[] = {
      {q(dir + "/none.json") + " -o " + q(out), "none.json: cannot open scene file"},
      {q(scene) + " --spp 1 -o " + q(out), "2 ranks for 1 samples per pixel"},
      {q(caustics) + " -o " + q(out),
       "integrator.caustics: part files and MPI ranks cannot hold light-traced caustics yet"},
      {"-x LUCENT_KERNEL_DIR=" + q(kernels) + " " + prog + q(scene) + " -o " + q(out),
       "megakernel.cl:"}};
  // (all at once: each is a 2-rank job refused before rendering, mostly MPI's start and end)
  std::vector<std::string> commands;
  for (const auto& [args, says] : cases) {
    const bool env = args.rfind("-x ", 0) == 0;  // mpirun's option, then the program
    commands.push_back("timeout 60 env " + mpirun("-np 2 " + (env ? "" : prog) + args));
  }
  const std::vector<CommandResult> results = run_shells_together(commands, dir);
  for (size_t i = 0; i < std::size(cases); ++i) {
    const auto& [args, says] = cases[i];
    const bool env = args.rfind("-x ", 0) == 0;
    const CommandResult& r = results[i];
    EXPECT_EQ(r.status, 1) << args << "\n" << r.err;
    EXPECT_EQ(lucent_mpi_lines(r.err), 1) << args << "\n" << r.err;
    const size_t line = r.err.find("lucent-mpi: error: rank 0 of 2 (");
    ASSERT_NE(line, std::string::npos) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(says, line), std::string::npos) << args << "\n" << r.err;
    EXPECT_EQ(r.err.find("MPI_ABORT"), std::string::npos) << args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out)) << args;
    if (env) {  // the build log its line refers to ("build log above"), once, as lucent says it
      EXPECT_NE(r.err.find("(build log above)"), std::string::npos) << r.err;
      const size_t log = r.err.find("kernel build log:\n");
      EXPECT_LT(log, line) << r.err;
      EXPECT_EQ(r.err.find("kernel build log:", log + 1), std::string::npos) << r.err;
      EXPECT_NE(r.err.find("unknown type name 'lucent_injected_error'", log), std::string::npos)
          << r.err;
    }
  }
}

// A stop signal during the kernel build is an interruption, as for `lucent render`
// (Outputs.SigtermDuringTheKernelBuildIsAnInterruption): PoCL's LLVM handles the signal too while
// it builds, and the build fails, which ended the job through MPI_Abort ("kernel build failed",
// status 1). The kernel caches off (PoCL's in an empty directory each time: a build the signal
// did not fail fills it), the build takes about a second here (a whole LLVM compilation): SIGTERM
// to the ranks 0 or 80 ms after both locked their checkpoints (their handlers are installed
// then; a rank killed in MPI_Init could hang mpirun), before their sessions open a device, comes
// before rendering on a machine ten times faster than this one too, during the device's opening
// or the build; wherever it comes there, the outcome is the same: every rank ends, one line
// ("interrupted by SIGTERM before rendering: nothing written"), status 143, no output.
TEST(Parts, MpiSigtermDuringTheKernelBuildIsAnInterruption) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  // (the slowest of the MPI entries, 6-12 s each under the sanitizers: the release build runs
  // them; the sanitizer build runs the other lucent-mpi entries, which take the same paths)
  if (lucent::test::kAddressSanitizer) GTEST_SKIP() << "slow under AddressSanitizer";
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string script = dir + "/stop.sh", err = dir + "/mpi.err";
  const std::string lock0 = dir + "/ck.rank0-of-2.exr.lock",
                    lock1 = dir + "/ck.rank1-of-2.exr.lock";
  for (int ms = 0; ms <= 80; ms += 80) {
    SCOPED_TRACE(std::to_string(ms) + " ms");
    for (const std::string& name : names_with(dir, "ck.")) fs::remove(dir + "/" + name);
    lucent::test::write_file(
        script, "timeout 60 env POCL_CACHE_DIR=" + q(dir + "/pocl" + std::to_string(ms)) +
                    " LUCENT_CACHE_DIR=off " +
                    mpirun("-np 2 '" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) +
                           " --spp 16000000 -o " + q(dir + "/mpi.exr") + " --checkpoint " +
                           q(dir + "/ck.exr")) +
                    " 2>" + q(err) + " </dev/null & pid=$!\n" + "for i in $(seq 3000); do [ -e " +
                    q(lock0) + " ] && [ -e " + q(lock1) + " ] && break; sleep 0.01; done\nsleep " +
                    std::to_string(ms / 1000.0) +
                    "\nkill -TERM $(pgrep -P $(pgrep -P $pid))\nwait $pid\n");
    const int raw = std::system(("bash " + q(script)).c_str());
    const std::string text = lucent::test::read_file(err);
    ASSERT_TRUE(WIFEXITED(raw)) << text;
    EXPECT_EQ(WEXITSTATUS(raw), 143) << text;
    EXPECT_EQ(text.find("lucent-mpi: error:"), std::string::npos) << text;
    EXPECT_EQ(text.find("kernel build failed"), std::string::npos) << text;
    EXPECT_NE(text.find("interrupted by SIGTERM before rendering: nothing written"),
              std::string::npos)
        << text;
    EXPECT_EQ(lucent_mpi_lines(text), 1) << text;
    EXPECT_EQ(names_with(dir, "mpi.exr"), std::vector<std::string>{});
  }
}

// --checkpoint (docs/parts.md, "Checkpoints of lucent-mpi"): a render that is not stopped writes
// the image of the run without it, and leaves no checkpoint, lock or temporary file behind.
TEST(Parts, MpiCheckpointCompleteRunLeavesNoCheckpoint) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string prog = "-np 2 '" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) + " --spp 8";
  CommandResult r = run_shell(
      mpirun(prog + " -o " + q(dir + "/with.exr") + " --checkpoint " + q(dir + "/ck.exr")), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(names_with(dir, "ck."), std::vector<std::string>{}) << r.err;
  r = run_shell(mpirun(prog + " -o " + q(dir + "/without.exr")), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const lucent::RenderPart with = lucent::read_render_part(dir + "/with.exr");
  const lucent::RenderPart without = lucent::read_render_part(dir + "/without.exr");
  EXPECT_EQ(with.info.samples, (std::vector<lucent::SampleRange>{{0, 8}}));
  EXPECT_LT(max_relative_difference(with.acc, without.acc), 1e-5);
}

// A checkpoint of a run that asked for more samples (another --spp, the scene's spp edited),
// resumed by one that asks for fewer: the output requests this run's samples. It kept the
// checkpoint's request, so that a merge said samples were missing from a complete render (one
// rank), and rank 0 refused a rank's share once it was rendered, at every rerun (several).
TEST(Parts, MpiCheckpointOfALargerRequestResumesToThisRunsRequest) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir), ck = dir + "/ck.exr", out = dir + "/out.exr";
  auto command = [&](const std::string& spp, const std::string& time) {
    return mpirun("-np 1 '" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) + " --spp " + spp +
                  time + " -o " + q(out) + " --checkpoint " + q(ck));
  };
  CommandResult r = run_shell(command("16000000", " --time 0.3"), dir);  // stopped short
  const std::string rank_ck = dir + "/ck.rank0-of-1.exr";
  ASSERT_TRUE(fs::exists(rank_ck)) << r.err;
  const lucent::PartInfo held = lucent::read_part_info(rank_ck);
  ASSERT_EQ(held.requested, (std::vector<lucent::SampleRange>{{0, 16000000}}));
  const std::uint64_t spp = held.samples.back().end + 4;
  r = run_shell(command(std::to_string(spp), ""), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const lucent::PartInfo whole = lucent::read_part_info(out);
  EXPECT_EQ(whole.samples, (std::vector<lucent::SampleRange>{{0, spp}}));
  EXPECT_EQ(whole.requested, (std::vector<lucent::SampleRange>{{0, spp}}));
  r = run_cli("merge --complete " + q(out) + " -o " + q(dir + "/m.exr"));
  EXPECT_EQ(r.status, 0) << r.err;
}

// mpirun's A : B gives ranks arguments of their own: --checkpoint on some ranks only is refused
// with one line before anything is written or locked. The ranks with a checkpoint take collective
// steps that the others skip, and such a job hung for ever (here: until the timeout, status 124).
TEST(Parts, MpiCheckpointOnSomeRanksOnlyIsRefused) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string out = dir + "/out.exr";
  const std::string prog = "'" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) + " --spp 8 -o " +
                           q(out),
                    with = prog + " --checkpoint " + q(dir + "/ck.exr");
  for (const std::string& ranks :
       {"-np 1 " + with + " : -np 1 " + prog, "-np 1 " + prog + " : -np 2 " + with}) {
    SCOPED_TRACE(ranks);
    CommandResult r = run_shell("timeout 20 env " + mpirun(ranks), dir);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(lucent_mpi_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("lucent-mpi: error: rank 0 of "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("another rank has "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("give every rank the same --checkpoint"), std::string::npos) << r.err;
    EXPECT_EQ(names_with(dir, "ck."), std::vector<std::string>{});
    EXPECT_FALSE(fs::exists(out));
  }
}

// Another --spp moves the ranks' shares: rank 1's checkpoint no longer starts at its share and is
// refused, with one line. Rank 0, whose checkpoint still fits its share, said first that it was
// resuming from it (a line for a render that never ran): that is said once every rank agreed.
TEST(Parts, MpiCheckpointRefusedResumeIsOneLine) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  auto command = [&](const std::string& spp) {
    return mpirun("-np 2 '" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) + " --spp " + spp +
                  " --time 0.5 -o " + q(dir + "/out.exr") + " --checkpoint " + q(dir + "/ck.exr"));
  };
  // --time stops both ranks far short of their shares: each writes its checkpoint
  CommandResult r = run_shell(command("16000000"), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(fs::exists(dir + "/ck.rank0-of-2.exr") && fs::exists(dir + "/ck.rank1-of-2.exr"))
      << r.err;
  const std::string bytes1 = lucent::test::read_file(dir + "/ck.rank1-of-2.exr");
  r = run_shell("timeout 60 env " + command("12000000"), dir);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(lucent_mpi_lines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.find("resuming"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("lucent-mpi: error: rank 1 of 2 ("), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ck.rank1-of-2.exr: holds samples [8000000, "), std::string::npos) << r.err;
  // (the hint named `lucent render --samples` alone)
  EXPECT_NE(r.err.find("not a checkpoint's [6000000, K) (a part of `lucent render --samples`, or a "
                       "lucent-mpi rank's checkpoint: of another rank, or of another --spp, which "
                       "moves the ranks' shares?)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(lucent::test::read_file(dir + "/ck.rank1-of-2.exr"), bytes1);
  // the output's name as the checkpoint's, as `lucent render` refuses it (the ranks' files have
  // names of their own, and it was taken)
  r = run_shell("timeout 60 env " + mpirun("-np 2 '" + std::string(LUCENT_MPI_PATH) + "' " +
                                           q(scene) + " --spp 4 -o " + q(dir + "/out.exr") +
                                           " --checkpoint " + q(dir + "/out.exr")),
                dir);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(lucent_mpi_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(dir + "/out.exr: is the output too"), std::string::npos) << r.err;
}

// A rank whose checkpoint write fails (a full disk; here a file size limit on rank 1 alone, under
// the 10 MB of its 400x400 checkpoint) warns and goes on; rank 0's last line names the samples the
// checkpoints hold, not the output's (it said they held rank 1's samples, in no file).
TEST(Parts, MpiCheckpointFailedWriteIsNotClaimed) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string limited = dir + "/limited.sh";
  // (SIGXFSZ ignored: a write past the limit fails with EFBIG instead of ending the rank)
  lucent::test::write_file(limited, "trap '' XFSZ\nulimit -f 6000\nexec \"$@\"\n");
  const std::string prog = "'" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) +
                           " --width 400 --height 400 --spp 16000000 --time 1 -o " +
                           q(dir + "/out.exr") + " --checkpoint " + q(dir + "/ck.exr");
  // --time stops both ranks far short of their shares: each writes its checkpoint
  CommandResult r = run_shell(
      "timeout 60 env " + mpirun("-np 1 " + prog + " : -np 1 bash " + q(limited) + " " + prog),
      dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("lucent-mpi: rank 1 of 2: warning: checkpoint not written: " + dir +
                       "/ck.rank1-of-2.exr: cannot write (File too large)"),
            std::string::npos)
      << r.err;
  ASSERT_TRUE(fs::exists(dir + "/ck.rank0-of-2.exr")) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/ck.rank1-of-2.exr")) << r.err;
  const lucent::PartInfo out = lucent::read_part_info(dir + "/out.exr");
  ASSERT_EQ(out.samples.size(), 2u) << r.err;
  EXPECT_EQ(out.samples[1].begin, 8000000u);
  const lucent::PartInfo ck0 = lucent::read_part_info(dir + "/ck.rank0-of-2.exr");
  ASSERT_EQ(ck0.samples.size(), 1u) << r.err;
  EXPECT_NE(
      r.err.find("lucent-mpi: the checkpoints " + dir + "/ck.rank<r>-of-2.exr hold samples " +
                 lucent::range_text(ck0.samples[0]) +
                 " of [0, 16000000) (not all of the output's " + lucent::ranges_text(out.samples) +
                 ": a checkpoint was not written): the same command with 2 ranks resumes "
                 "the render"),
      std::string::npos)
      << r.err;
}

// Rank 0's write of the output fails after a complete render (a full disk; here a file size limit
// on rank 0 alone, which the 2.4 MB PFM exceeds and the 75 KB checkpoints of this flat image do
// not): every rank's checkpoint then holds its whole share (they held none: the default
// --checkpoint-every is 300 s, up to which every rank's work was lost), rank 0 says so after one
// line for the output, and the same command renders nothing and writes the uninterrupted image.
TEST(Parts, MpiCheckpointFailedOutputWriteKeepsEveryRanksSamples) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  // (the slowest of the MPI entries, 6-12 s each under the sanitizers: the release build runs
  // them; the sanitizer build runs the other lucent-mpi entries, which take the same paths)
  if (lucent::test::kAddressSanitizer) GTEST_SKIP() << "slow under AddressSanitizer";
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = lucent::test::flat_lamp_scene(dir);  // 75 KB parts, 2.4 MB PFMs
  const std::string ck = dir + "/ck.exr", out = dir + "/out.pfm", full = dir + "/full.pfm";
  const std::string prog = "'" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) + " -q -o ";
  // (first: the kernel caches are filled, whose files the limit would refuse)
  CommandResult r = run_shell("timeout 60 env " + mpirun("-np 2 " + prog + q(full)), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string limited = dir + "/limited.sh";
  // (SIGXFSZ ignored: a write past the limit fails with EFBIG instead of ending the rank)
  lucent::test::write_file(limited, "trap '' XFSZ\nulimit -f 1500\nexec \"$@\"\n");
  const std::string with = prog + q(out) + " --checkpoint " + q(ck);
  r = run_shell(
      "timeout 60 env " + mpirun("-np 1 bash " + q(limited) + " " + with + " : -np 1 " + with),
      dir);
  EXPECT_NE(r.status, 0) << r.err;
  EXPECT_EQ(lucent_mpi_lines(r.err), 2) << r.err;
  EXPECT_NE(r.err.find("lucent-mpi: error: rank 0 of 2 ("), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("): " + out + ": cannot write (File too large)\n"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("lucent-mpi: the checkpoints " + dir +
                       "/ck.rank<r>-of-2.exr hold samples [0, 4) of [0, 4): the same command "
                       "with 2 ranks writes the output\n"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out));
  ASSERT_TRUE(fs::exists(dir + "/ck.rank0-of-2.exr") && fs::exists(dir + "/ck.rank1-of-2.exr"))
      << r.err;
  EXPECT_EQ(lucent::read_part_info(dir + "/ck.rank0-of-2.exr").samples,
            (std::vector<lucent::SampleRange>{{0, 2}}));
  EXPECT_EQ(lucent::read_part_info(dir + "/ck.rank1-of-2.exr").samples,
            (std::vector<lucent::SampleRange>{{2, 4}}));

  // the same command: nothing rendered (each rank's checkpoint holds its share), the output
  // written, the checkpoints gone
  r = run_shell("timeout 60 env " + mpirun("-np 2 " + with), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(names_with(dir, "ck."), std::vector<std::string>{}) << r.err;
  const lucent::Image resumed = lucent::read_image(out), single = lucent::read_image(full);
  ASSERT_EQ(resumed.rgb.size(), single.rgb.size());
  for (size_t i = 0; i < resumed.rgb.size(); ++i)
    ASSERT_NEAR(resumed.rgb[i], single.rgb[i], 1e-5 * std::abs(single.rgb[i])) << i;
}

// The checkpoints of another number of ranks are refused, and the line names what to remove to
// start again: the checkpoints, their locks and the hidden temporary files of a write killed
// half-way, which a run of that count removes and this one does not ("ck.rank*-of-2.exr" left
// the last two for ever). Removing what it names leaves none of the old run's files, and the
// render runs.
TEST(Parts, MpiCheckpointOfAnotherRankCountNamesAllItsFiles) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  for (const char* name : {"ck.rank0-of-2.exr", "ck.rank0-of-2.exr.lock", "ck.rank1-of-2.exr",
                           "ck.rank1-of-2.exr.lock", ".ck.rank1-of-2.exr.tmp-4242-0"})
    lucent::test::write_file(dir + "/" + name, "the old run's");
  const std::string command =
      mpirun("-np 1 '" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) + " -q --spp 8 -o " +
             q(dir + "/out.exr") + " --checkpoint " + q(dir + "/ck.exr"));
  CommandResult r = run_shell("timeout 60 env " + command, dir);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(lucent_mpi_lines(r.err), 1) << r.err;
  const std::string head =
                        ": a checkpoint of a run of 2 ranks, this one has 1: resume it with "
                        "mpirun -np 2, or remove ",
                    tail = " to start again";
  const size_t at = r.err.find(head), end = r.err.find(tail);
  ASSERT_NE(at, std::string::npos) << r.err;
  ASSERT_NE(end, std::string::npos) << r.err;
  std::string patterns = r.err.substr(at + head.size(), end - at - head.size());
  EXPECT_EQ(patterns, dir + "/ck.rank*-of-2.exr* and " + dir + "/.ck.rank*-of-2.exr.tmp-*");
  if (const size_t and_at = patterns.find(" and "); and_at != std::string::npos)
    patterns.replace(and_at, 5, " ");
  ASSERT_EQ(std::system(("bash -c " + q("rm -f -- " + patterns)).c_str()), 0);
  EXPECT_EQ(names_with(dir, "-of-2"), std::vector<std::string>{});
  r = run_shell("timeout 60 env " + command, dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir + "/out.exr"));
}

// A rank's checkpoint needs its part and the part file's write beside the session, as `lucent
// render --checkpoint` counts them: at 2048x2048 (1.1 GiB), under an address-space limit that the
// render without a checkpoint fits, the rank refuses before rendering instead of failing its first
// checkpoint write.
TEST(Parts, MpiCheckpointMemoryIsCountedBeforeRendering) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  if (lucent::test::kAddressSanitizer)
    GTEST_SKIP() << "AddressSanitizer cannot run under ulimit -v";
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string out = dir + "/mpi.png";
  CommandResult r = run_shell("ulimit -v 1500000; timeout 60 env " +
                                  mpirun("-np 1 '" + std::string(LUCENT_MPI_PATH) + "' " +
                                         q(scene) + " --width 2048 --height 2048 --spp 1 -o " +
                                         q(out) + " --checkpoint " + q(dir + "/ck.exr")),
                              dir);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("lucent-mpi: error: rank 0 of 1 ("), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the largest part is what the application keeps beside the session (its "
                       "outputs, as it declared them) (1.1 GiB)"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(dir + "/ck.rank0-of-1.exr"));

  // the ranks other than 0 keep their part and write their checkpoint after the session: refused
  // before rendering too (ulimit 1.2 GB: 937.5 MiB allowed, rank 0's merge and PNG fit), with one
  // line where each of them printed its own, and before any lock is taken
  r = run_shell("ulimit -v 1200000; timeout 60 env " +
                    mpirun("-np 3 '" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) +
                           " --width 2048 --height 2048 --spp 3 -o " + q(out) + " --checkpoint " +
                           q(dir + "/ck.exr")),
                dir);
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(lucent_mpi_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("lucent-mpi: error: rank 1 of 3 ("), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the largest part is writing " + dir + "/ck.rank1-of-3.exr (2048x2048)"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(names_with(dir, "-of-3"), std::vector<std::string>{});
}

// A job stopped by SIGTERM (Slurm's at its time limit) keeps each rank's checkpoint of its own
// range; the same command resumes every rank where its checkpoint ends and writes the image of the
// uninterrupted run. Another number of ranks, or a checkpoint of another seed, is refused with one
// line before rendering, writing nothing.
TEST(Parts, MpiCheckpointStoppedRunResumesToTheUninterruptedImage) {
  if (!have_mpirun()) GTEST_SKIP() << LUCENT_MPIEXEC << " is absent";
  // (the slowest of the MPI entries, 6-12 s each under the sanitizers: the release build runs
  // them; the sanitizer build runs the other lucent-mpi entries, which take the same paths)
  if (lucent::test::kAddressSanitizer) GTEST_SKIP() << "slow under AddressSanitizer";
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string ck = dir + "/ck.exr", out = dir + "/out.exr", full = dir + "/full.exr";
  const std::string ck0 = dir + "/ck.rank0-of-2.exr", ck1 = dir + "/ck.rank1-of-2.exr";
  // about 1 s of rendering per rank for two ranks sharing this device (12x10: a CPU's rate
  // measured by a render of 0.5 s); the checkpoints every 0.2 s appear a fraction of the way in
  const double rate = lucent::test::cli_samples_per_second(scene, dir + "/cal.exr");
  ASSERT_GT(rate, 0) << "the calibration render failed";
  std::uint64_t n = 0;
  auto command = [&](int ranks, const std::string& extra) {
    return mpirun("-np " + std::to_string(ranks) + " '" + std::string(LUCENT_MPI_PATH) + "' " +
                  q(scene) + " --spp " + std::to_string(n) + " -o " + q(out) + " --checkpoint " +
                  q(ck) + " --checkpoint-every 0.2" + extra);
  };
  // SIGTERM to the ranks (mpirun's children) once
  // both checkpoints exist. A machine faster than at the calibration can finish first: tried
  // again with twice the samples, up to 3 times
  const std::string script = dir + "/stop.sh";
  std::string text;
  for (int attempt = 0; attempt < 3; ++attempt) {
    n = std::clamp<std::uint64_t>(std::uint64_t(rate * 1.0 / 120) << attempt, 20000,
                                  std::uint64_t(1) << 24);
    lucent::test::write_file(
        script, command(2, "") + " 2>" + q(dir + "/stop.err") + " </dev/null & pid=$!\n" +
                    "for i in $(seq 600); do [ -e " + q(ck0) + " ] && [ -e " + q(ck1) +
                    " ] && break; kill -0 $pid 2>/dev/null || break; sleep 0.05; done\n" +
                    "kill -TERM $(pgrep -P $pid)\nwait $pid\n");
    const int raw = std::system(("bash " + q(script)).c_str());
    text = lucent::test::read_file(dir + "/stop.err");
    // finished before the stop (the checkpoints removed; or kept, with every rank's whole share,
    // when the signal came after the last pass): again, longer
    auto ends_at = [](const std::string& ck, std::uint64_t end) {
      const lucent::PartInfo info = lucent::read_part_info(ck);
      return info.samples.size() == 1 && info.samples[0].end == end;
    };
    const bool both = fs::exists(ck0) && fs::exists(ck1);
    if ((!both && !fs::exists(ck0) && !fs::exists(ck1)) ||
        (both && ends_at(ck0, n / 2) && ends_at(ck1, n))) {
      for (const std::string& name : names_with(dir, "ck.")) fs::remove(dir + "/" + name);
      fs::remove(out);
      continue;
    }
    ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) != 0) << text;
    break;
  }
  ASSERT_TRUE(fs::exists(ck0) && fs::exists(ck1)) << text;
  const lucent::PartInfo info0 = lucent::read_part_info(ck0), info1 = lucent::read_part_info(ck1);
  ASSERT_EQ(info0.samples.size(), 1u) << text;
  ASSERT_EQ(info1.samples.size(), 1u) << text;
  const std::uint64_t k0 = info0.samples[0].end, k1 = info1.samples[0].end;
  EXPECT_EQ(info0.samples[0].begin, 0u);
  EXPECT_EQ(info1.samples[0].begin, n / 2);
  EXPECT_EQ(info0.requested, (std::vector<lucent::SampleRange>{{0, n / 2}}));
  EXPECT_EQ(info1.requested, (std::vector<lucent::SampleRange>{{n / 2, n}}));
  EXPECT_TRUE(k0 < n / 2 || k1 < n) << "the render ended before the stop";
  // adjacent ranges joined: a rank 0 that finished its share before the stop holds [0, n / 2)
  const std::string held = k0 == n / 2
                               ? "[0, " + std::to_string(k1) + ")"
                               : "[0, " + std::to_string(k0) + "), [" + std::to_string(n / 2) +
                                     ", " + std::to_string(k1) + ")";
  EXPECT_NE(text.find("lucent-mpi: the checkpoints " + dir + "/ck.rank<r>-of-2.exr hold samples " +
                      held + " of [0, " + std::to_string(n) +
                      "): the same command with 2 ranks resumes the render"),
            std::string::npos)
      << text;

  // refused before rendering: one line, the checkpoints, the output and the directory as they were
  const std::string bytes0 = lucent::test::read_file(ck0), bytes1 = lucent::test::read_file(ck1);
  const std::string output = lucent::test::read_file(out);
  const std::vector<std::string> files = names_with(dir, "ck.");
  for (const auto& [ranks, extra, says] : std::vector<std::tuple<int, std::string, std::string>>{
           {3, "",
            "-of-2.exr: a checkpoint of a run of 2 ranks, this one has 3: resume it with "
            "mpirun -np 2, or remove " +
                dir + "/ck.rank*-of-2.exr* and " + dir +
                "/.ck.rank*-of-2.exr.tmp-* to start again"},
           {2, " --seed 9", "ck.rank0-of-2.exr: seed 3 differs from " + scene + "'s 9"}}) {
    SCOPED_TRACE(std::to_string(ranks) + extra);
    CommandResult r = run_shell("timeout 60 env " + command(ranks, extra), dir);
    EXPECT_NE(r.status, 0);
    EXPECT_EQ(lucent_mpi_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("lucent-mpi: error: rank 0 of " + std::to_string(ranks) + " ("),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_EQ(names_with(dir, "ck."), files);  // (no lock, no checkpoint of this run)
    EXPECT_EQ(lucent::test::read_file(ck0), bytes0);
    EXPECT_EQ(lucent::test::read_file(ck1), bytes1);
    EXPECT_EQ(lucent::test::read_file(out), output);
  }

  // the same command: each rank resumes its range, and the checkpoints go
  CommandResult r = run_shell(command(2, ""), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  if (k0 > 0) {
    EXPECT_NE(r.err.find("lucent-mpi: rank 0 of 2: resuming from " + ck0 +
                         ", which holds samples [0, " + std::to_string(k0) + ")"),
              std::string::npos)
        << r.err;
  }
  EXPECT_EQ(names_with(dir, "ck."), std::vector<std::string>{}) << r.err;
  ASSERT_EQ(run_shell(mpirun("-np 2 '" + std::string(LUCENT_MPI_PATH) + "' " + q(scene) +
                             " -q --spp " + std::to_string(n) + " -o " + q(full)),
                      dir)
                .status,
            0);
  const lucent::RenderPart resumed = lucent::read_render_part(out);
  const lucent::RenderPart single = lucent::read_render_part(full);
  EXPECT_EQ(resumed.info.samples, (std::vector<lucent::SampleRange>{{0, n}}));
  EXPECT_LT(max_relative_difference(resumed.acc, single.acc), 1e-5);
}
#else
TEST(Parts, MpiTwoRanksRenderTheOneProcessImage) {
  GTEST_SKIP() << "lucent-mpi is not built (no MPI found; see LUCENT_MPI)";
}
#endif

}  // namespace

}  // namespace test_parts
