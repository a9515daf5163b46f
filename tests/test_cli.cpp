// The command-line front end: --version, --help, the render options and the progress line
// (interrupting a render: tests/test_outputs.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "lucent/compare.hpp"
#include "support.hpp"

namespace test_cli {

namespace {

using lucent::test::CommandResult;
using lucent::test::run_cli;

std::string q(const std::string& s) { return "'" + s + "'"; }

std::string read_all(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(line);
  return out;
}

// A plane of albedo (0.25, 0.5, 0.75) filling the view, lit by a point light; path traced by
// default, so the image is noisy and depends on the seed. Exact image comparisons use 2 spp: the
// renderer always runs that as two passes of 1, so the float sums are the same every time.
std::string plane_scene(int seed = 0, int spp = 2, const std::string& integrator = "path") {
  std::string path = lucent::test::temp_dir() + "/plane.json";
  lucent::test::write_file(path, R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 20},
    "film": {"width": 16, "height": 16, "filter": {"type": "gaussian"}},
    "integrator": {"type": ")" + integrator +
                                     R"(", "spp": )" + std::to_string(spp) + R"(, "seed": )" +
                                     std::to_string(seed) + R"(},
    "materials": {"m": {"type": "diffuse", "albedo": [0.25, 0.5, 0.75]}},
    "shapes": [{"type": "triangles", "material": "m",
                "positions": [[-10,-10,0],[10,-10,0],[10,10,0],[-10,10,0]],
                "indices": [0,1,2, 0,2,3]},
               {"type": "sphere", "center": [0.3, 0.2, 0.5], "radius": 0.3, "material": "m"}],
    "lights": [{"type": "point", "position": [0.7, 0.4, 2.0], "intensity": [20, 20, 20]},
               {"type": "environment", "radiance": [0.2, 0.2, 0.2]}]
  })");
  return path;
}

lucent::Image render_to(const std::string& scene, const std::string& extra) {
  std::string out = lucent::test::temp_dir() + "/out.pfm";
  CommandResult r = run_cli("render " + q(scene) + " -o " + q(out) + " --quiet " + extra);
  EXPECT_EQ(r.status, 0) << r.err;
  return lucent::read_image(out);
}

TEST(Cli, Version) {
  CommandResult r = run_cli("--version");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out, std::string("lucent ") + lucent::kVersion + "\n");
  EXPECT_TRUE(r.err.empty()) << r.err;
}

// `lucent devices` is a table whose columns line up, however long a device's name (PoCL's CPU
// device names itself in 49 characters, wider than the column was, and shifted every column
// after it).
TEST(Cli, DevicesColumnsLineUp) {
  const CommandResult r = run_cli("devices");
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream lines(r.out);
  std::string header, row;
  ASSERT_TRUE(std::getline(lines, header));
  const std::size_t type = header.find(" type ");
  ASSERT_NE(type, std::string::npos) << header;
  int rows = 0;
  while (std::getline(lines, row)) {
    ++rows;
    ASSERT_GT(row.size(), type + 1) << row;
    EXPECT_EQ(row[type], ' ') << row;      // the device column ends where the header's does
    EXPECT_NE(row[type + 1], ' ') << row;  // and the type starts under "type"
  }
  EXPECT_GE(rows, 1);
}

TEST(Cli, HelpOnEachSubcommand) {
  CommandResult r = run_cli("--help");
  ASSERT_EQ(r.status, 0);
  // the subcommands listed by the top-level help
  std::vector<std::string> commands;
  bool in_list = false;
  for (const std::string& line : lines_of(r.out)) {
    if (line.rfind("Subcommands:", 0) == 0) {
      in_list = true;
      continue;
    }
    if (in_list && line.rfind("  ", 0) == 0) {
      std::istringstream in(line);
      std::string name;
      in >> name;
      commands.push_back(name);
    }
  }
  for (const char* expected : {"render", "devices", "info"})
    EXPECT_NE(std::find(commands.begin(), commands.end(), expected), commands.end())
        << expected << " missing from:\n"
        << r.out;
  for (const std::string& c : commands) {
    for (const char* flag : {"--help", "-h"}) {
      CommandResult h = run_cli(c + " " + flag);
      EXPECT_EQ(h.status, 0) << c << " " << flag << ": " << h.err;
      EXPECT_NE(h.out.find("Usage: lucent " + c), std::string::npos) << h.out;
      EXPECT_TRUE(h.err.empty()) << h.err;
    }
  }
  CommandResult h = run_cli("render --help");
  for (const char* option : {"--output", "--spp", "--width", "--height", "--seed", "--device",
                             "--quiet", "--time", "--integrator", "LUCENT_DEVICE"})
    EXPECT_NE(h.out.find(option), std::string::npos) << option << " missing from:\n" << h.out;
}

// README.md's "Command line" documents every option of every subcommand, as --help lists them.
TEST(Cli, ReadmeDocumentsEveryOption) {
  std::string readme = read_all(lucent::test::source_path("README.md"));
  size_t begin = readme.find("## Command line"), end = readme.find("\n## ", begin + 1);
  ASSERT_NE(begin, std::string::npos);
  std::string section = readme.substr(begin, end - begin);
  std::vector<std::string> commands;
  for (const std::string& line : lines_of(run_cli("--help").out))
    if (line.rfind("  ", 0) == 0 && line.find_first_not_of(' ') == 2 && line[2] != '-')
      commands.push_back(line.substr(2, line.find(' ', 2) - 2));
  ASSERT_GE(commands.size(), 6u);
  const std::regex option("(^|[ ,])(--?[a-z][a-z0-9-]*)");
  int checked = 0;
  for (const std::string& c : commands) {
    EXPECT_NE(section.find("lucent " + c), std::string::npos) << c;
    for (const std::string& line : lines_of(run_cli(c + " --help").out)) {
      if (line.rfind("  -", 0) != 0) continue;  // option lines start with two spaces and a dash
      std::string names = line.substr(0, line.find_first_of(" ", line.find_first_not_of(' ')));
      for (std::sregex_iterator it(names.begin(), names.end(), option), stop; it != stop; ++it) {
        std::string name = (*it)[2];
        if (name == "-h" || name == "--help") continue;
        ++checked;
        // the name, not a longer option it begins (--reference in --reference-spp)
        EXPECT_TRUE(std::regex_search(section, std::regex(name + "(?![a-z0-9-])")))
            << "lucent " << c << " " << name << " is not in README.md's Command line";
      }
    }
  }
  EXPECT_GE(checked, 30);
}

TEST(Cli, WidthAndHeightSetTheImageSize) {
  std::string scene = plane_scene();
  std::string dir = lucent::test::temp_dir();
  CommandResult r = run_cli("render " + q(scene) + " -o " + q(dir + "/a.png") +
                            " --width 37 --height 23 --spp 1 --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  lucent::Image png = lucent::read_image(dir + "/a.png");
  EXPECT_EQ(png.width, 37);
  EXPECT_EQ(png.height, 23);
  lucent::Image pfm = render_to(scene, "--width 5 --spp 1");
  EXPECT_EQ(pfm.width, 5);
  EXPECT_EQ(pfm.height, 16);  // from the scene
  for (const std::string ext : {".exr", ".PNG"}) {
    r = run_cli("render " + q(scene) + " -o " + q(dir + "/b" + ext) + " --height 9 --spp 1 -q");
    ASSERT_EQ(r.status, 0) << ext << ": " << r.err;
    lucent::Image img = lucent::read_image(dir + "/b" + ext);
    EXPECT_EQ(img.width, 16) << ext;
    EXPECT_EQ(img.height, 9) << ext;
  }
}

// Same seed, same image; --seed replaces the scene's seed.
TEST(Cli, SeedSelectsTheRandomSequence) {
  std::string seed0 = plane_scene(0), seed7 = plane_scene(7);
  lucent::Image a = render_to(seed0, "--seed 7");
  lucent::Image b = render_to(seed0, "--seed 7");
  lucent::Image c = render_to(seed7, "");
  lucent::Image d = render_to(seed0, "--seed 8");
  lucent::Image e = render_to(seed0, "");
  ASSERT_EQ(a.rgb.size(), 16u * 16u * 3u);
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_EQ(a.rgb, c.rgb) << "--seed 7 differs from the scene's seed 7";
  EXPECT_NE(a.rgb, d.rgb);
  EXPECT_NE(a.rgb, e.rgb) << "--seed had no effect";
}

TEST(Cli, SppIsReported) {
  std::string scene = plane_scene(0, 4);
  std::string out = lucent::test::temp_dir() + "/o.pfm";
  CommandResult r = run_cli("render " + q(scene) + " -o " + q(out) + " --spp 3");
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> lines = lines_of(r.err);
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines.back().rfind(out + ": 16x16, 3 spp in ", 0), 0u) << lines.back();
  r = run_cli("render " + q(scene) + " -o " + q(out));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find(out + ": 16x16, 4 spp in "), std::string::npos) << r.err;  // the scene's
}

TEST(Cli, IntegratorOverride) {
  std::string scene = plane_scene();
  // the albedo integrator returns the first hit's albedo, exactly
  lucent::Image albedo = render_to(scene, "--integrator albedo --spp 2");
  for (size_t i = 0; i < albedo.rgb.size(); i += 3) {
    EXPECT_FLOAT_EQ(albedo.rgb[i], 0.25f);
    EXPECT_FLOAT_EQ(albedo.rgb[i + 1], 0.5f);
    EXPECT_FLOAT_EQ(albedo.rgb[i + 2], 0.75f);
  }
  lucent::Image path = render_to(scene, "--spp 2");
  EXPECT_NE(path.rgb, albedo.rgb);
  // and the other way round: a scene asking for albedo, rendered with --integrator path
  lucent::Image back = render_to(plane_scene(0, 2, "albedo"), "--integrator path");
  EXPECT_EQ(back.rgb, path.rgb);
}

// --max-depth and --rr-depth override the scene's integrator.max_depth and rr_depth: the same
// image as a scene file that asks for them (2 spp: the same float sums), black at max_depth 1
// (the plane fills the view and emits nothing), and another image than the scene's depth 8
TEST(Cli, DepthOverrides) {
  std::string scene = plane_scene();
  std::string text = read_all(scene);
  const std::string key = "\"seed\": 0";
  ASSERT_NE(text.find(key), std::string::npos);
  std::string own = lucent::test::temp_dir() + "/depths.json";
  lucent::test::write_file(
      own, text.replace(text.find(key), key.size(), key + ", \"max_depth\": 2, \"rr_depth\": 1"));
  lucent::Image flag = render_to(scene, "--max-depth 2 --rr-depth 1");
  EXPECT_EQ(flag.rgb, render_to(own, "").rgb);
  EXPECT_NE(flag.rgb, render_to(scene, "").rgb);
  lucent::Image camera_only = render_to(scene, "--max-depth 1");
  for (float v : camera_only.rgb) EXPECT_EQ(v, 0.0f);
  EXPECT_NE(run_cli("render " + q(scene) + " -o " + q(lucent::test::temp_dir() + "/x.pfm") +
                    " --max-depth 0")
                .status,
            0);
}

// A render longer than a second prints a progress line (percent, samples/s, elapsed, ETA);
// --time stops it (the scene asks for 2^24 spp); --quiet silences everything.
// --aov: each AOV lands beside the image as <stem>.<name>.exr (float EXR), rendered on the same
// session with the main render's spp, so each equals the library's render of that integrator
// at the same seed and spp (the variance: the main render's own), and they say what they are:
// the albedo of every pixel is the material's, the depths are the plane's 5 along the axis and
// the sphere's nearer, the primitive ids are the sphere (1) and the two triangles (2, 3).
// (The AOVs' values themselves: KernelVsReference.Aovs and ReferenceAnalytic.AovsOnAPlane.)
TEST(Cli, AovsAreWrittenBesideTheImage) {
  std::string scene = plane_scene();
  std::string dir = lucent::test::temp_dir();
  CommandResult r = run_cli("render " + q(scene) + " -o " + q(dir + "/x.exr") +
                            " --aov albedo --aov depth --aov variance --aov primitive");
  ASSERT_EQ(r.status, 0) << r.err;
  const lucent::Scene sc = lucent::load_scene(scene);
  lucent::RenderOptions o;
  o.spp = 2;
  const lucent::RenderResult main_render = lucent::test::render(sc, o);
  EXPECT_EQ(lucent::read_image(dir + "/x.exr").rgb, main_render.mean.rgb);
  std::map<std::string, lucent::Image> aov;
  for (const std::string name : {"albedo", "depth", "variance", "primitive"}) {
    const std::string path = dir + "/x." + name + ".exr";
    EXPECT_NE(r.err.find(path + ": " + name + " AOV\n"), std::string::npos) << r.err;
    aov[name] = lucent::read_image(path);
    ASSERT_EQ(aov[name].rgb.size(), 16u * 16u * 3u) << name;
    if (name == "variance") {
      EXPECT_EQ(aov[name].rgb, main_render.variance.rgb);
    } else {
      lucent::Scene s = sc;
      s.integrator.type = *lucent::find_type<lucent::IntegratorType>(name);
      const lucent::RenderResult expected = lucent::test::render(s, o);
      EXPECT_EQ(aov[name].rgb, expected.mean.rgb) << name;
      // with the render's statistics, as --integrator NAME -o writes it: without them lucent
      // compare took a noisy AOV (ao) for an exact image
      const lucent::RenderResult written = lucent::read_render(path);
      ASSERT_EQ(written.samples.size(), 16u * 16u) << name;
      for (std::uint32_t n : written.samples) EXPECT_EQ(n, 2u) << name;
      EXPECT_EQ(written.variance.rgb, expected.variance.rgb) << name;
    }
  }
  const std::vector<float>& albedo = aov["albedo"].rgb;
  for (size_t i = 0; i < albedo.size(); i += 3)
    EXPECT_TRUE(albedo[i] == 0.25f && albedo[i + 1] == 0.5f && albedo[i + 2] == 0.75f) << i;
  const std::vector<float>& depth = aov["depth"].rgb;
  const float centre = depth[(8 * 16 + 8) * 3];  // 0.5 to 1.5 pixels off the axis: the plane
  EXPECT_NEAR(centre, 5.0f, 0.01f);
  EXPECT_NEAR(*std::min_element(depth.begin(), depth.end()), 4.2f, 0.05f);  // the sphere's front
  // (averaged over the pixel's two samples: 1.5 or 2.5 on an edge)
  std::set<float> ids(aov["primitive"].rgb.begin(), aov["primitive"].rgb.end());
  for (float id : {1.0f, 2.0f, 3.0f}) EXPECT_EQ(ids.count(id), 1u) << id;
  EXPECT_GE(*ids.begin(), 1.0f);
  EXPECT_LE(*ids.rbegin(), 3.0f);
  const std::vector<float>& var = aov["variance"].rgb;
  EXPECT_GT(*std::max_element(var.begin(), var.end()), 0.0f) << "path tracing is noisy";
}

// An AOV whose values are not radiance (depth, normal, primitive), written as an 8-bit image: the
// display transform and [0, 1] clip it in a file that looks complete (a depth image of a scene 5
// away was a white silhouette): a warning says so, and names the formats that keep them.
TEST(Cli, AovValuesToAnEightBitImageAreSaidToBeClipped) {
  const std::string scene = plane_scene(0, 1);
  const std::string dir = lucent::test::temp_dir();
  for (const char* integrator : {"depth", "normal", "primitive", "albedo"}) {
    CommandResult r =
        run_cli("render " + q(scene) + " -o " + q(dir + "/a.png") + " --integrator " + integrator);
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string warning = "lucent: warning: " + dir + "/a.png: the " + integrator +
                                " integrator's values are not radiance: an 8-bit image clips "
                                "them to [0, 1] after the film's display transform; write .exr "
                                "or .pfm to keep them\n";
    EXPECT_EQ(r.err.find(warning) != std::string::npos, std::string(integrator) != "albedo")
        << r.err;
    r = run_cli("render " + q(scene) + " -o " + q(dir + "/a.exr") + " --integrator " + integrator);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  }
}

TEST(Cli, ProgressLineAndTimeLimit) {
  std::string scene = plane_scene(0, 1 << 24);
  std::string out = lucent::test::temp_dir() + "/o.png";
  CommandResult r = run_cli("render " + q(scene) + " -o " + q(out) + " --time 1.5 --width 64");
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> lines = lines_of(r.err);
  ASSERT_GE(lines.size(), 2u) << r.err;
  const std::string duration = R"(\d+(\.\d|m\d\d)s)";  // 12.3s or 4m05s
  std::regex progress(R"(^ *\d+\.\d%  \d+ spp  \d+\.\d\d Msamples/s  elapsed )" + duration +
                      "  ETA " + duration + "$");
  for (size_t i = 0; i + 1 < lines.size(); ++i)
    EXPECT_TRUE(std::regex_match(lines[i], progress)) << "progress line: " << lines[i];
  EXPECT_EQ(lines.back().rfind(out + ": 64x16, ", 0), 0u) << lines.back();
  lucent::Image img = lucent::read_image(out);
  EXPECT_EQ(img.width, 64);

  r = run_cli("render " + q(scene) + " -o " + q(out) + " --time 1.5 --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out, "");

  // --spp N that the time limit stopped short: said (the summary's "2651 spp" said not of what)
  r = run_cli("render " + q(scene) + " -o " + q(out) + " --time 0.5 --spp 16777216");
  ASSERT_EQ(r.status, 0) << r.err;
  lines = lines_of(r.err);
  ASSERT_GE(lines.size(), 2u) << r.err;
  EXPECT_TRUE(std::regex_match(
      lines.back(),
      std::regex(".*o\\.png: the time limit stopped it at \\d+ of the 16777216 spp asked for")))
      << r.err;
}

// A render shorter than a second prints no progress line; under LUCENT_TEST_EARLY_PROGRESS=1 (the
// stop-signal tests' sign that the render loop runs, kEarlyProgress) it does from its first pass.
TEST(Cli, ProgressLineFromTheFirstPassForTheStopSignalTests) {
  const std::string scene = plane_scene(0, 4);
  const std::string out = lucent::test::temp_dir() + "/o.png";
  const std::regex progress(R"(^ *\d+\.\d%  \d+ spp  \d+\.\d\d Msamples/s  elapsed )");
  CommandResult r = run_cli("render " + q(scene) + " -o " + q(out));
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> lines = lines_of(r.err);
  ASSERT_EQ(lines.size(), 1u) << r.err;
  EXPECT_EQ(lines[0].rfind(out + ": ", 0), 0u) << r.err;
  r = run_cli("render " + q(scene) + " -o " + q(out), lucent::test::kEarlyProgress);
  ASSERT_EQ(r.status, 0) << r.err;
  lines = lines_of(r.err);
  ASSERT_EQ(lines.size(), 2u) << r.err;
  EXPECT_TRUE(std::regex_search(lines[0], progress)) << r.err;
  EXPECT_EQ(lines[1].rfind(out + ": ", 0), 0u) << r.err;
}

// --target-error with a --time that ends the render in its pilot: the summary says so and the
// warning line names the time limit (it printed neither: the render looked complete, exit 0).
TEST(Cli, AdaptiveStoppedInThePilotByTheTimeLimitSaysSo) {
  std::string scene = plane_scene(0, 2);
  std::string out = lucent::test::temp_dir() + "/a.exr";
  CommandResult r = run_cli("render " + q(scene) + " -o " + q(out) +
                            " --target-error 1e-4 --min-spp 64 --time 0.000001");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::regex_search(
      r.err,
      std::regex(out + ": adaptive: stopped in its pilot, \\d+ of \\d+ spp on average: no plan "
                       "made, the error not estimated \\(target 0.0001\\)\n")))
      << r.err;
  EXPECT_TRUE(std::regex_search(
      r.err, std::regex("lucent: warning: " + out +
                        ": the time limit stopped the render in its pilot, at \\d+ of its \\d+ "
                        "spp: no plan was made and the error is not estimated \\(target "
                        "0.0001\\): raise --time\n$")))
      << r.err;
}

// ... and one that ends it after its pilot, short of its plan: the summary line says so (it read
// as a render that had completed its plan).
TEST(Cli, AdaptiveStoppedByTheTimeLimitAfterItsPilotSaysSo) {
  std::string scene = plane_scene(0, 2);
  std::string out = lucent::test::temp_dir() + "/a.exr";
  CommandResult r = run_cli("render " + q(scene) + " -o " + q(out) +
                            " --target-error 1e-9 --min-spp 4 --spp 1000000 --time 0.3");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::regex_search(
      r.err, std::regex(out + ": adaptive: \\d+ spp on average, .*; the time limit stopped it at "
                              "\\d+ of the \\d+ spp its plan asked for\n")))
      << r.err;
}

// On a terminal the progress line is redrawn in place ('\r') and the summary starts a new line.
// `script` (util-linux) gives the CLI a pseudo-terminal.
TEST(Cli, ProgressLineOnATerminal) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "no script(1)";
  std::string scene = plane_scene(0, 1 << 24);
  std::string dir = lucent::test::temp_dir();
  std::string out = dir + "/o.png", log = dir + "/tty.log";
  std::string inner = std::string("'") + LUCENT_CLI_PATH + "' render " + q(scene) + " -o " +
                      q(out) + " --time 1.5 --width 64";
  std::string cmd = "script -qec " + q(inner) + " /dev/null </dev/null >" + q(log) + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << read_all(log);
  std::string text = read_all(log);
  EXPECT_TRUE(
      std::regex_search(text, std::regex(R"(\r *\d+\.\d%  \d+ spp  .* Msamples/s  elapsed )")))
      << text;
  EXPECT_NE(text.find("\n" + out + ": 64x16, "), std::string::npos) << text;
  EXPECT_EQ(text.find("lucent: error"), std::string::npos) << text;
}

}  // namespace

}  // namespace test_cli
