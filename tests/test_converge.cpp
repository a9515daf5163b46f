// lucent converge (lucent/converge.hpp): setting syntax, the log-log fit and the bias verdict on
// synthetic curves, then kernel ladders against a kernel reference (error falls as 1/spp for the
// scene's own setting; a shallow max_depth is flagged biased), the CSV, the SVG plot and the CLI.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <atomic>
#include <cctype>
#include <clocale>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "image/plot_svg.hpp"
#include "lucent/compare.hpp"
#include "lucent/converge.hpp"
#include "lucent/error.hpp"
#include "lucent/limits.hpp"
#include "lucent/session.hpp"
#include "render/converge_noise.hpp"
#include "support.hpp"

namespace test_converge {

namespace {

using lucent::ConvergeFit;
using lucent::ConvergePoint;
using lucent::ConvergeSetting;

// Diffuse spheres on a diffuse floor under a uniform sky: a quarter of the light is indirect
// (interreflections between the spheres and the floor), and with a single environment light
// there is no light selection to make the variance heavy-tailed.
const char* kScene = R"({
  "camera": {"position": [0, 1.0, 4], "look_at": [0, 0.5, 0], "fov": 45},
  "film": {"width": 32, "height": 24},
  "integrator": {"type": "path", "max_depth": 8, "rr_depth": 8, "spp": 16, "seed": 3},
  "materials": {"white": {"type": "diffuse", "albedo": [0.8, 0.8, 0.8]},
                "red": {"type": "diffuse", "albedo": [0.8, 0.3, 0.2]}},
  "shapes": [
    {"type": "sphere", "center": [0, -100, 0], "radius": 100, "material": "white"},
    {"type": "sphere", "center": [-0.6, 0.6, 0], "radius": 0.6, "material": "red"},
    {"type": "sphere", "center": [0.7, 0.5, -0.3], "radius": 0.5, "material": "white"}
  ],
  "lights": [{"type": "environment", "radiance": [1, 1, 1]}]
})";

std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, sep);) out.push_back(item);
  return out;
}

/// "" when `x` is UTF-8 (shortest forms, no surrogates, at most U+10FFFF) of XML 1.0 characters
/// only (tab, newline, CR, U+0020..U+D7FF, U+E000..U+FFFD, U+10000..U+10FFFF), else the first
/// offending byte's offset.
std::string check_xml_chars(const std::string& x) {
  for (size_t i = 0; i < x.size();) {
    const unsigned char c = static_cast<unsigned char>(x[i]);
    const int n = c < 0x80                ? 1
                  : c >= 0xC2 && c < 0xE0 ? 2
                  : c >= 0xE0 && c < 0xF0 ? 3
                  : c >= 0xF0 && c < 0xF5 ? 4
                                          : 0;
    std::uint32_t cp = n == 1 ? c : n == 2 ? c & 0x1Fu : n == 3 ? c & 0x0Fu : c & 0x07u;
    bool ok = n > 0 && i + n <= x.size();
    for (int k = 1; ok && k < n; ++k) {
      const unsigned char d = static_cast<unsigned char>(x[i + k]);
      ok = (d >> 6) == 2;
      cp = (cp << 6) | (d & 0x3Fu);
    }
    const std::uint32_t min[] = {0, 0, 0x80, 0x800, 0x10000};
    ok = ok && cp >= min[n] &&
         (cp == 0x9 || cp == 0xA || cp == 0xD || (cp >= 0x20 && cp <= 0xD7FF) ||
          (cp >= 0xE000 && cp <= 0xFFFD) || (cp >= 0x10000 && cp <= 0x10FFFF));
    if (!ok) return "not an XML 1.0 character in UTF-8 at byte " + std::to_string(i);
    i += static_cast<size_t>(n);
  }
  return "";
}

/// A minimal XML well-formedness check: UTF-8 of XML 1.0 characters, declaration, comments,
/// start/end/empty tags with quoted attributes, properly nested, one root element, only the
/// predefined or numeric entities. Returns "" when well formed, else what is wrong. Counts the
/// start tags named `count_tag`.
std::string check_xml(const std::string& x, const std::string& count_tag, int* count) {
  *count = 0;
  if (std::string e = check_xml_chars(x); !e.empty()) return e;
  std::vector<std::string> stack;
  int roots = 0;
  *count = 0;
  size_t i = 0;
  auto is_name = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == ':' ||
           c == '.';
  };
  auto check_text = [](const std::string& t) -> std::string {
    for (size_t k = 0; k < t.size(); ++k) {
      if (t[k] == '<') return "'<' in text";
      if (t[k] != '&') continue;
      size_t semi = t.find(';', k);
      if (semi == std::string::npos) return "unterminated entity";
      std::string e = t.substr(k + 1, semi - k - 1);
      if (e != "amp" && e != "lt" && e != "gt" && e != "quot" && e != "apos" &&
          !(e.size() > 1 && e[0] == '#'))
        return "unknown entity &" + e + ";";
    }
    return "";
  };
  while (i < x.size()) {
    size_t lt = x.find('<', i);
    std::string text = x.substr(i, lt == std::string::npos ? std::string::npos : lt - i);
    if (std::string e = check_text(text); !e.empty()) return e;
    if (stack.empty() && text.find_first_not_of(" \t\r\n") != std::string::npos)
      return "text outside the root element";
    if (lt == std::string::npos) break;
    if (x.compare(lt, 5, "<?xml") == 0) {
      if (lt != 0) return "XML declaration not at the start";
      size_t end = x.find("?>", lt);
      if (end == std::string::npos) return "unterminated declaration";
      i = end + 2;
      continue;
    }
    if (x.compare(lt, 4, "<!--") == 0) {
      size_t end = x.find("-->", lt);
      if (end == std::string::npos) return "unterminated comment";
      i = end + 3;
      continue;
    }
    size_t j = lt + 1;
    bool closing = j < x.size() && x[j] == '/';
    if (closing) ++j;
    size_t name_start = j;
    while (j < x.size() && is_name(x[j])) ++j;
    std::string name = x.substr(name_start, j - name_start);
    if (name.empty()) return "tag without a name at " + std::to_string(lt);
    if (closing) {
      while (j < x.size() && std::isspace(static_cast<unsigned char>(x[j]))) ++j;
      if (j >= x.size() || x[j] != '>') return "malformed end tag </" + name;
      if (stack.empty() || stack.back() != name) return "mismatched end tag </" + name + ">";
      stack.pop_back();
      i = j + 1;
      continue;
    }
    // attributes: name="value" or name='value'
    bool empty = false;
    for (;;) {
      while (j < x.size() && std::isspace(static_cast<unsigned char>(x[j]))) ++j;
      if (j >= x.size()) return "unterminated tag <" + name;
      if (x[j] == '>') break;
      if (x.compare(j, 2, "/>") == 0) {
        empty = true;
        ++j;
        break;
      }
      size_t a = j;
      while (j < x.size() && is_name(x[j])) ++j;
      if (j == a) return "bad attribute in <" + name;
      if (j >= x.size() || x[j] != '=') return "attribute without a value in <" + name;
      ++j;
      if (j >= x.size() || (x[j] != '"' && x[j] != '\'')) return "unquoted attribute in <" + name;
      size_t close = x.find(x[j], j + 1);
      if (close == std::string::npos) return "unterminated attribute in <" + name;
      if (std::string e = check_text(x.substr(j + 1, close - j - 1)); !e.empty()) return e;
      j = close + 1;
    }
    if (name == count_tag) ++*count;
    if (stack.empty()) ++roots;
    if (!empty) stack.push_back(name);
    i = j + 1;
  }
  if (!stack.empty()) return "unclosed <" + stack.back() + ">";
  if (roots != 1) return std::to_string(roots) + " root elements";
  return "";
}

std::vector<ConvergePoint> synthetic(const std::vector<double>& relmse,
                                     const std::vector<double>& noise) {
  std::vector<ConvergePoint> pts;
  for (size_t i = 0; i < relmse.size(); ++i) {
    ConvergePoint p;
    p.setting = "s";
    p.spp = 1u << (i + 2);
    p.seconds = 0.01 * double(p.spp);
    p.relmse = relmse[i];
    p.noise_relmse = noise[i];
    pts.push_back(p);
  }
  return pts;
}
// A process whose numbers are written with a decimal comma (a Python program that called
// locale.setlocale(locale.LC_ALL, "") on a German system): the CSV, the SVG and the settings
// keep the C locale's "0.5". The CSV held "0,25" in comma-separated fields, the SVG
// x1="80,00", and "clamp=0.5" was refused. Found by running lucent.converge from Python under
// de_DE.UTF-8. Skipped where no such locale is installed (LOCPATH may name a directory of one).
TEST(Converge, NumbersIgnoreTheProcessLocale) {
  const std::string before = std::setlocale(LC_NUMERIC, nullptr);
  const char* comma = nullptr;
  for (const char* name : {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8", "de_DE",
                           "fr_FR", "nl_NL.UTF-8", "ru_RU.UTF-8"})
    if (std::setlocale(LC_NUMERIC, name) && std::string(std::localeconv()->decimal_point) == ",") {
      comma = name;
      break;
    }
  struct Restore {
    std::string name;
    ~Restore() { std::setlocale(LC_NUMERIC, name.c_str()); }
  } restore{before};
  if (!comma) GTEST_SKIP() << "no locale with a decimal comma is installed";
  char probe[16];
  std::snprintf(probe, sizeof probe, "%.1f", 0.5);
  ASSERT_STREQ(probe, "0,5") << comma;

  EXPECT_EQ(lucent::parse_converge_setting("clamp=0.5").clamp, 0.5);
  EXPECT_EQ(lucent::parse_converge_setting("filter=gaussian:1.25").filter_radius, 1.25);
  lucent::ConvergeResult r;
  for (int i = 0; i < 3; ++i) {
    lucent::ConvergePoint p;
    p.setting = "default";
    p.spp = 1u << i;
    p.seconds = 0.25 * (i + 1);
    p.samples_per_second = 1.5e6;
    p.rmse = 0.5 / (i + 1);
    p.relmse = 0.125 / (i + 1);
    r.points.push_back(p);
  }
  r.fits.push_back(lucent::fit_convergence(r.points));
  const std::string csv = lucent::convergence_csv(r);
  EXPECT_NE(csv.find("default,1,0.25,1.5e+06,0.5,0.125,"), std::string::npos) << csv;
  const std::string svg = lucent::convergence_svg(r, "t");
  EXPECT_FALSE(std::regex_search(svg, std::regex("=\"[-0-9]+,[0-9]+\""))) << svg.substr(0, 400);
  int paths = 0;
  EXPECT_EQ(check_xml(svg, "path", &paths), "");
  // this thread's locale is the process's again
  std::snprintf(probe, sizeof probe, "%.1f", 0.5);
  EXPECT_STREQ(probe, "0,5");
}

TEST(Converge, SettingSyntax) {
  ConvergeSetting d = lucent::parse_converge_setting("default");
  EXPECT_EQ(d.name, "default");
  EXPECT_FALSE(d.fast_math);
  EXPECT_TRUE(d.specialize);
  EXPECT_EQ(d.max_depth, 0);

  ConvergeSetting s = lucent::parse_converge_setting("max_depth=2+fast-math+no-mis+filter=box:0.7");
  EXPECT_EQ(s.name, "max_depth=2+fast-math+no-mis+filter=box:0.7");
  EXPECT_EQ(s.max_depth, 2);
  EXPECT_TRUE(s.fast_math);
  EXPECT_EQ(s.mis, 0);
  EXPECT_EQ(s.filter, static_cast<int>(lucent::FilterType::Box));
  EXPECT_DOUBLE_EQ(s.filter_radius, 0.7);

  lucent::Scene scene = lucent::parse_scene(kScene, "t.json");
  lucent::RenderOptions opt;
  s.apply(scene, opt);
  EXPECT_EQ(scene.integrator.max_depth, 2);
  EXPECT_FALSE(scene.integrator.mis);
  EXPECT_EQ(scene.film.filter.type, lucent::FilterType::Box);
  EXPECT_DOUBLE_EQ(scene.film.filter.radius, 0.7);
  EXPECT_TRUE(opt.fast_math);
  EXPECT_TRUE(opt.specialize);
  lucent::parse_converge_setting("no-specialize").apply(scene, opt);
  EXPECT_FALSE(opt.specialize);
  EXPECT_EQ(scene.integrator.dielectric_splits, 2);
  lucent::parse_converge_setting("splits=0").apply(scene, opt);
  EXPECT_EQ(scene.integrator.dielectric_splits, 0);
  lucent::parse_converge_setting("splits=4").apply(scene, opt);
  EXPECT_EQ(scene.integrator.dielectric_splits, 4);

  // the sampling knobs (issue 12), parsed and applied
  ConvergeSetting k =
      lucent::parse_converge_setting("sampler=independent+clamp=10+caustics+rr-depth=3+mis");
  EXPECT_EQ(k.sampler, static_cast<int>(lucent::SamplerType::Independent));
  EXPECT_DOUBLE_EQ(k.clamp, 10.0);
  EXPECT_EQ(k.caustics, 1);
  EXPECT_EQ(k.rr_depth, 3);
  EXPECT_EQ(k.mis, 1);
  k.apply(scene, opt);
  EXPECT_EQ(scene.integrator.sampler, lucent::SamplerType::Independent);
  EXPECT_DOUBLE_EQ(scene.integrator.clamp, 10.0);
  EXPECT_TRUE(scene.integrator.caustics);
  EXPECT_EQ(scene.integrator.rr_depth, 3);
  EXPECT_TRUE(scene.integrator.mis);
  lucent::parse_converge_setting("no-caustics+clamp=0").apply(scene, opt);
  EXPECT_FALSE(scene.integrator.caustics);
  EXPECT_DOUBLE_EQ(scene.integrator.clamp, 0.0);
  ConvergeSetting a = lucent::parse_converge_setting("adaptive+min-spp=8");
  EXPECT_TRUE(a.adaptive);
  EXPECT_EQ(a.min_spp, 8);
  ConvergeSetting t = lucent::parse_converge_setting("target-error=1e-3+min-spp=16");
  EXPECT_DOUBLE_EQ(t.target_error, 1e-3);
  EXPECT_EQ(t.min_spp, 16);
  EXPECT_FALSE(t.adaptive);
  EXPECT_EQ(lucent::parse_converge_setting("integrator=direct").integrator,
            static_cast<int>(lucent::IntegratorType::Direct));
  EXPECT_EQ(lucent::test::error_of([] { lucent::parse_converge_setting("caustics+no-caustics"); }),
            "setting 'caustics+no-caustics': no-caustics and caustics set the same thing");
  // default twice was taken (fast-math twice refused), an empty filter radius read as none, and a
  // value starting with + was split at it ("setting max_depth=: ...")
  EXPECT_EQ(lucent::test::error_of([] { lucent::parse_converge_setting("default+default"); }),
            "setting 'default+default': default and default set the same thing");
  EXPECT_EQ(lucent::test::error_of([] { lucent::parse_converge_setting("filter=box:"); }),
            "setting filter=box:: an empty radius after ':' (filter=box alone, or "
            "filter=box:RADIUS)");
  EXPECT_EQ(lucent::test::error_of([] { lucent::parse_converge_setting("max_depth=+3"); }),
            "setting 'max_depth=+3': a value cannot start with + (+ joins knobs)");
  EXPECT_EQ(lucent::test::error_of([] { lucent::parse_converge_setting("filter=gaussian:+1"); }),
            "setting 'filter=gaussian:+1': a value cannot start with + (+ joins knobs)");
  // a number's knob as written, and the pilot's true range (it said min_spp, from 1)
  EXPECT_EQ(lucent::test::error_of([] { lucent::parse_converge_setting("adaptive+min-spp=-4"); }),
            "setting min-spp=-4: expected an integer from 4 to 16384");
  // at most an adaptive render's most samples per pixel (16384), which a study cannot raise: the
  // study failed at the setting, after rendering the reference and the settings before it
  EXPECT_EQ(lucent::test::error_of(
                [] { lucent::parse_converge_setting("target-error=1e-3+min-spp=20000"); }),
            "setting min-spp=20000: expected an integer from 4 to 16384");
  EXPECT_EQ(lucent::parse_converge_setting("adaptive+min-spp=16383").min_spp, 16383);
  EXPECT_EQ(lucent::test::error_of([] { lucent::parse_converge_setting("max-depth=0"); }),
            "setting max-depth=0: expected an integer from 1 to 100000");
  // a number that is no plain decimal says so (03 is in range, 0x10 is >= 0)
  EXPECT_EQ(lucent::test::error_of([] { lucent::parse_converge_setting("max_depth=03"); }),
            "setting max_depth=03: expected an integer from 1 to 100000 in plain decimal");
  EXPECT_EQ(lucent::test::error_of([] { lucent::parse_converge_setting("clamp=0x10"); }),
            "setting clamp=0x10: expected a number >= 0 in plain decimal");

  for (const char* bad :
       {"", "bogus", "max_depth=0", "max_depth=x", "max_depth", "fast-math=1", "filter=round",
        "filter=box:-1", "default+nope", "splits=5", "splits=-1", "splits", "sampler=halton",
        "clamp=-1", "clamp=x", "clamp", "target-error=0", "target-error=nan", "adaptive+min-spp=2",
        "min-spp=8", "adaptive+target-error=1e-3", "integrator=bogus", "mis=1", "caustics=1",
        // two knobs setting one thing: the last one won without a word
        "caustics+no-caustics", "clamp=1+clamp=2", "float+double", "mis+no_mis",
        // numbers in plain decimal, as the command line's (strtol and strtod took these), and
        // no empty knob (a trailing + was dropped)
        "max_depth=03", "max_depth= 3", "max_depth=+3", "splits=0x1", "clamp=0x10", "clamp= 1",
        "target-error=0x1p-10", "filter=tent:0x1", "filter=box: 1", "max_depth=3+", "+mis",
        "mis++fast-math"}) {
    try {
      lucent::parse_converge_setting(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const lucent::Error& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
}

// A ConvergeSetting made in code is checked as the parser's are (the API tester's finds): mis = 5
// turned MIS on where caustics = 7 turned caustics off; a max_depth of -5, a NaN clamp or a NaN
// target meant "the scene's" without a word; two settings of the same knobs rendered twice.
TEST(Converge, SettingsMadeInCodeAreChecked) {
  const std::pair<std::function<void(ConvergeSetting&)>, std::string> cases[] = {
      {[](ConvergeSetting& s) { s.mis = 5; }, "mis must be -1 (the scene's), 0 or 1"},
      {[](ConvergeSetting& s) { s.caustics = 7; }, "caustics must be -1 (the scene's), 0 or 1"},
      {[](ConvergeSetting& s) { s.max_depth = -5; }, "max_depth must be 0 (the scene's) to 100000"},
      {[](ConvergeSetting& s) { s.clamp = std::nan(""); },
       "clamp must be < 0 (the scene's) or a number from 0 to 3.4e38"},
      {[](ConvergeSetting& s) { s.target_error = std::nan(""); },
       "target_error must be 0 (off) or a positive number"},
      {[](ConvergeSetting& s) { s.integrator = 99; },
       "integrator must be -1 (the scene's) or an IntegratorType"},
      {[](ConvergeSetting& s) { s.splits = 9; }, "splits must be -1 (the scene's) to 4"},
      {[](ConvergeSetting& s) { s.filter_radius = -1; },
       "filter_radius must be 0 (the scene's) or in (0, 8]"},
      {[](ConvergeSetting& s) {
         s.adaptive = true;
         s.target_error = 1e-3;
       },
       "adaptive and target-error exclude each other"},
      {[](ConvergeSetting& s) { s.min_spp = 8; }, "min-spp needs adaptive or target-error"}};
  for (const auto& [alter, message] : cases) {
    lucent::ConvergeOptions opt;
    opt.spp_ladder = {1, 2};
    ConvergeSetting s;
    s.name = "made";
    alter(s);
    opt.settings = {s};
    EXPECT_EQ(lucent::test::error_of([&] { lucent::check_convergence_options(opt); }),
              "converge: setting 'made': " + message);
  }
  lucent::ConvergeOptions opt;
  opt.spp_ladder = {1, 2};
  ConvergeSetting a, b;
  a.name = "a";
  b.name = "b";
  opt.settings = {a, b};
  EXPECT_EQ(lucent::test::error_of([&] { lucent::check_convergence_options(opt); }),
            "converge: setting 'b' sets what setting 'a' sets (each would render the same)");
  b.max_depth = 3;
  opt.settings = {a, b};
  EXPECT_NO_THROW(lucent::check_convergence_options(opt));
}

TEST(Converge, DefaultLadder) {
  EXPECT_EQ(lucent::default_spp_ladder(64), (std::vector<int>{1, 2, 4, 8, 16, 32, 64}));
  EXPECT_EQ(lucent::default_spp_ladder(48), (std::vector<int>{1, 2, 4, 8, 16, 32, 48}));
  EXPECT_EQ(lucent::default_spp_ladder(1), (std::vector<int>{1}));
  // from the API, past 2^30: an int doubling overflowed and the loop never ended
  const std::vector<int> big = lucent::default_spp_ladder(1 << 30);
  EXPECT_EQ(big.size(), 31u);
  EXPECT_EQ(big.back(), 1 << 30);
  const std::vector<int> top = lucent::default_spp_ladder(std::numeric_limits<int>::max());
  EXPECT_EQ(top.size(), 32u);
  EXPECT_EQ(top.back(), std::numeric_limits<int>::max());
}

// The library refuses the ladders the command line refuses (lucent::limits: 1 .. 2^24 spp, up to
// 1e7 s): a caller of the API gave a rung of 2^31 - 1 spp or 1e300 s, which ran until killed.
TEST(Converge, LaddersBeyondTheLimitsAreRefused) {
  lucent::ConvergeOptions opt;
  opt.spp_ladder = {1, lucent::limits::kMaxSpp};
  EXPECT_NO_THROW(lucent::check_convergence_options(opt));
  for (int bad : {0, lucent::limits::kMaxSpp + 1, std::numeric_limits<int>::max()}) {
    opt.spp_ladder = {1, bad};
    EXPECT_EQ(lucent::test::error_of([&] { lucent::check_convergence_options(opt); }),
              "converge: spp ladder values must be in [1, 16777216], got " + std::to_string(bad));
  }
  opt.spp_ladder.clear();
  opt.time_ladder = {0.5, 1e7};
  EXPECT_NO_THROW(lucent::check_convergence_options(opt));
  for (double bad : {0.0, -1.0, 1.0001e7, 1e300, std::numeric_limits<double>::infinity(),
                     std::numeric_limits<double>::quiet_NaN()}) {
    opt.time_ladder = {0.5, bad};
    const std::string msg = lucent::test::error_of([&] { lucent::check_convergence_options(opt); });
    EXPECT_EQ(msg.rfind("converge: time ladder values must be in (0, 1e7] seconds, got ", 0), 0u)
        << msg;
  }
  // a rung given twice (an spp rung rendered the same image twice, and the fit said "n/a")
  opt.time_ladder = {0.5, 1, 0.5};
  EXPECT_EQ(lucent::test::error_of([&] { lucent::check_convergence_options(opt); }),
            "converge: the time ladder gives 0.5 s twice (each budget is one rung)");
  opt.time_ladder.clear();
  opt.spp_ladder = {4, 8, 4};
  EXPECT_EQ(lucent::test::error_of([&] { lucent::check_convergence_options(opt); }),
            "converge: the spp ladder gives 4 twice (each sample count is one rung)");
  opt.spp_ladder = {8, 4};  // (any order)
  EXPECT_NO_THROW(lucent::check_convergence_options(opt));
}

// The default reference renders 16 x the top rung, at least 256 and at most 2^24 spp
// (--reference-spp's largest: a rung past 2^20 made it up to 2^28 without a word); 1024 for a
// time ladder.
TEST(Converge, DefaultReferenceStaysWithinTheSampleLimit) {
  EXPECT_EQ(lucent::default_reference_spp({1, 2, 4}), 256);
  EXPECT_EQ(lucent::default_reference_spp({64, 4}), 1024);
  EXPECT_EQ(lucent::default_reference_spp({1 << 20}), 1 << 24);
  EXPECT_EQ(lucent::default_reference_spp({(1 << 20) + 1}), lucent::limits::kMaxSpp);
  EXPECT_EQ(lucent::default_reference_spp({lucent::limits::kMaxSpp}), lucent::limits::kMaxSpp);
  EXPECT_EQ(lucent::default_reference_spp({}), 1024);
}

// excess_standard_error against synthetic renders of a known answer: each channel of 20x20 pixels
// the mean of n = 16 Gaussian samples around the reference R (spreads differing per pixel), its
// variance estimated from the samples as a render's is. Unbiased, z = (relMSE - noise_relmse) /
// excess_standard_error is standard normal to within the 400 pixels' central limit: over 300
// renders its mean is within 4 standard errors of 0 (|m| < 4 / sqrt(300) = 0.23) and its standard
// deviation in [0.85, 1.15] (that of 300 normals has a standard deviation of 0.04). A bias spread
// over every pixel, of the noise's size, is more than 4 standard errors out (about 6.5: "biased"
// needs 3); the same squared bias in 2 pixels about sqrt(2) (ConvergeFit's "undetermined": a few
// pixels hold it).
TEST(Converge, ExcessStandardErrorIsCalibrated) {
  using lucent::converge_detail::excess_standard_error;
  using lucent::converge_detail::noise_relmse;
  const int w = 20, h = 20, n = 16;
  const size_t channels = size_t(w) * h * 3;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  lucent::RenderResult ref;
  ref.mean = lucent::Image{w, h, std::vector<float>(channels)};
  std::vector<double> sigma(channels);
  double noise = 0;  // the expected noise_relmse
  for (size_t i = 0; i < channels; ++i) {
    ref.mean.rgb[i] = static_cast<float>(0.1 + 0.9 * double((i * 37) % 101) / 100.0);
    sigma[i] = 0.05 + 0.5 * double((i * 53) % 97) / 96.0;
    const double r = ref.mean.rgb[i];
    noise += sigma[i] * sigma[i] / n / (r * r + 0.01) / double(channels);
  }
  auto render = [&](const std::vector<double>& bias) {
    lucent::RenderResult a;
    a.mean = lucent::Image{w, h, std::vector<float>(channels)};
    a.variance = lucent::Image{w, h, std::vector<float>(channels)};
    a.samples.assign(channels / 3, n);
    for (size_t i = 0; i < channels; ++i) {
      double s = 0, s2 = 0;
      for (int k = 0; k < n; ++k) {
        const double x = ref.mean.rgb[i] + bias[i] + sigma[i] * gauss(rng);
        s += x;
        s2 += x * x;
      }
      a.mean.rgb[i] = static_cast<float>(s / n);
      a.variance.rgb[i] = static_cast<float>((s2 - s * s / n) / (n - 1));
    }
    return a;
  };
  auto z = [&](const lucent::RenderResult& a) {
    double relmse = 0;
    for (size_t i = 0; i < channels; ++i) {
      const double r = ref.mean.rgb[i], d = a.mean.rgb[i] - r;
      relmse += d * d / (r * r + 0.01) / double(channels);
    }
    const double se = excess_standard_error(a, ref);
    EXPECT_GT(se, 0);
    return (relmse - noise_relmse(a, ref)) / se;
  };
  const std::vector<double> none(channels, 0.0);
  const int renders = 300;
  double sum = 0, sumsq = 0;
  for (int t = 0; t < renders; ++t) {
    const double v = z(render(none));
    sum += v;
    sumsq += v * v;
  }
  const double mean = sum / renders, sd = std::sqrt((sumsq - sum * mean) / (renders - 1));
  EXPECT_LT(std::abs(mean), 0.23);
  EXPECT_GT(sd, 0.85);
  EXPECT_LT(sd, 1.15);
  // a squared bias of the noise's size (relMSE twice the noise), over every pixel-channel
  std::vector<double> spread(channels);
  for (size_t i = 0; i < channels; ++i) spread[i] = sigma[i] / std::sqrt(double(n));
  EXPECT_GT(z(render(spread)), 4);
  // the same, in the 6 channels of pixels 0 and 1
  std::vector<double> confined(channels, 0.0);
  for (size_t i = 0; i < 6; ++i) {
    const double r = ref.mean.rgb[i];
    confined[i] = std::sqrt(noise * double(channels) / 6 * (r * r + 0.01));
  }
  const double zc = z(render(confined));
  EXPECT_GT(zc, 0.5);
  EXPECT_LT(zc, 3);
}

TEST(Converge, FitOfSyntheticCurves) {
  // pure noise, relMSE = 0.5 / spp: slope exactly -1 against spp and against time (t ~ spp)
  std::vector<double> e, floor_e, flat_noise;
  for (int i = 0; i < 5; ++i) {
    double n = 0.5 / double(1 << (i + 2));
    e.push_back(n);
    floor_e.push_back(n + 0.05);  // plus a squared bias of 0.05
  }
  ConvergeFit f = lucent::fit_convergence(synthetic(e, e));
  EXPECT_NEAR(f.slope_spp, -1.0, 1e-9);
  EXPECT_NEAR(f.slope_time, -1.0, 1e-9);
  EXPECT_NEAR(f.excess_ratio, 1.0, 1e-9);
  EXPECT_FALSE(f.biased) << f.verdict;

  ConvergeFit b = lucent::fit_convergence(synthetic(floor_e, e));
  EXPECT_TRUE(b.biased);
  EXPECT_NEAR(b.bias_relmse, 0.05, 1e-9);
  EXPECT_GT(b.tail_slope_spp, -0.5);  // flattened
  // the noise (0.5/spp) equals the floor at 10 spp, i.e. 0.1 s with 0.01 s per spp
  EXPECT_NEAR(b.floor_seconds, 0.1, 1e-9);
  EXPECT_NE(b.verdict.find("biased: error stops decreasing at ~relMSE 5.00e-02"), std::string::npos)
      << b.verdict;

  // the threshold: error 10% above the noise is still unbiased, 50% above is biased
  std::vector<double> e11, e15;
  for (double v : e) {
    e11.push_back(1.1 * v);
    e15.push_back(1.5 * v);
  }
  EXPECT_FALSE(lucent::fit_convergence(synthetic(e11, e)).biased);
  ConvergeFit b15 = lucent::fit_convergence(synthetic(e15, e));
  EXPECT_TRUE(b15.biased);
  EXPECT_NEAR(b15.excess_ratio, 1.5, 1e-9);
  // the squared bias is half the last rung's noise: the noise falls to it at twice that rung's
  // time (0.64 s), i.e. 128 spp
  EXPECT_NEAR(b15.floor_seconds, 1.28, 1e-9);
  // ... unless that excess is within 3 standard errors of 0: a few pixels hold it, their rare
  // bright samples or a bias confined to them (the Cornell box was "biased" for 2 seeds of 15;
  // "unbiased", the first fix, of a bias in a few pixels): undetermined; over 3, biased
  std::vector<ConvergePoint> tail = synthetic(e15, e);
  tail.back().excess_standard_error = 0.5 * e.back() / 2.5;  // 2.5 standard errors
  const ConvergeFit t = lucent::fit_convergence(tail);
  EXPECT_FALSE(t.biased) << t.verdict;
  EXPECT_EQ(t.verdict,
            "undetermined (error/noise 1.50 at the last rung, but a few pixels hold the excess, "
            "2.5 standard errors: rare bright samples, or a bias confined to them; more samples "
            "tell)");
  tail.back().excess_standard_error = 0.5 * e.back() / 3.5;
  EXPECT_TRUE(lucent::fit_convergence(tail).biased);

  // the reference's share of the noise does not fall with time: only the render's own share is
  // extrapolated. A reference of the top rung's spp (64) holds half the noise at that rung: the
  // render's own noise there (0.5 / 64 / 2) equals the floor (0.5 * 0.5 / 64) at 0.64 s, 64 spp
  // (the whole noise extrapolated said 1.28 s, 128 spp)
  std::vector<ConvergePoint> half = synthetic(e15, e);
  for (ConvergePoint& p : half) p.reference_noise_relmse = 0.5 * e.back();
  ConvergeFit h = lucent::fit_convergence(half);
  EXPECT_TRUE(h.biased);
  EXPECT_NEAR(h.floor_seconds, 0.64, 1e-9);
  EXPECT_NE(h.verdict.find("after ~0.64 s, ~64 spp"), std::string::npos) << h.verdict;

  // without variance estimates the tail slope decides
  std::vector<double> zero(5, 0.0);
  EXPECT_FALSE(lucent::fit_convergence(synthetic(e, zero)).biased);
  EXPECT_TRUE(lucent::fit_convergence(synthetic(floor_e, zero)).biased);

  // one rung, or one spp repeated: no slope (they were 0.00, which reads as a measured one),
  // while the verdict from the noise estimate stands
  std::vector<ConvergePoint> one = synthetic({e[0]}, {e[0]});
  std::vector<ConvergePoint> same = synthetic(e, e);
  for (ConvergePoint& p : same) p.spp = 4, p.seconds *= 1 + 0.01 * double(&p - &same[0]);
  for (const auto& points : {one, same}) {
    const ConvergeFit g = lucent::fit_convergence(points);
    EXPECT_TRUE(std::isnan(g.slope_spp) && std::isnan(g.slope_time) && std::isnan(g.tail_slope_spp))
        << g.slope_spp << " " << g.slope_time << " " << g.tail_slope_spp;
    EXPECT_FALSE(g.biased);
    EXPECT_NE(g.verdict.find("unbiased (error/noise 1.00"), std::string::npos) << g.verdict;
  }
  // no variance estimate and fewer than three rungs: nothing tells (it said "unbiased"); an
  // error of 0 does
  EXPECT_EQ(lucent::fit_convergence(synthetic({e[0]}, {0.0})).verdict,
            "undetermined (no variance estimate, and too few rungs for a slope)");
  EXPECT_EQ(lucent::fit_convergence(synthetic({e[0], e[1]}, {0.0, 0.0})).verdict,
            "undetermined (no variance estimate, and too few rungs for a slope)");
  EXPECT_EQ(lucent::fit_convergence(synthetic({0.0, 0.0, 0.0, 0.0}, {0.0, 0.0, 0.0, 0.0})).verdict,
            "unbiased (no error at the last rung)");
}

TEST(Converge, KernelLadderAgainstKernelReference) {
  // independent samples: relMSE falls as 1/spp exactly (the Sobol sampler's slope is
  // Converge.SobolSlopeBeatsIndependent's)
  lucent::Scene scene =
      lucent::test::with_independent_samples(lucent::parse_scene(kScene, "t.json"));
  lucent::Scene ref_scene = scene;
  ref_scene.integrator.seed = lucent::reference_seed(scene.integrator.seed);
  ASSERT_NE(ref_scene.integrator.seed, scene.integrator.seed);
  lucent::RenderOptions ro;
  ro.spp = 1024;
  lucent::RenderResult reference = lucent::test::render(ref_scene, ro);

  lucent::ConvergeOptions opt;
  opt.render = lucent::test::render_options();
  opt.spp_ladder = {4, 8, 16, 32, 64};
  for (const char* s : {"default", "max_depth=1", "max_depth=2"})
    opt.settings.push_back(lucent::parse_converge_setting(s));
  lucent::ConvergeResult r = lucent::run_convergence(scene, reference, opt);
  ASSERT_EQ(r.points.size(), 15u);
  ASSERT_EQ(r.fits.size(), 3u);

  // The scene's own setting: the error is noise, which halves with each doubling of spp. Every
  // relMSE sums 2304 pixel-channel squared errors, so its relative spread is a few percent
  // (the rungs share samples); a factor 2 per rung leaves a wide margin for "decreasing", and
  // [-1.15, -0.85] for the fitted slope is about 5 of its standard deviations (the 1024-spp
  // reference's own noise adds 6% at the last rung, pulling the slope towards -0.97).
  for (size_t i = 1; i < 5; ++i) EXPECT_LT(r.points[i].relmse, r.points[i - 1].relmse) << i;
  const ConvergeFit& d = r.fits[0];
  EXPECT_EQ(d.setting, "default");
  EXPECT_GT(d.slope_spp, -1.15);
  EXPECT_LT(d.slope_spp, -0.85);
  EXPECT_FALSE(d.biased) << d.verdict;
  EXPECT_GT(d.excess_ratio, 0.7);
  EXPECT_LT(d.excess_ratio, 1.2);

  // max_depth 1 and 2 miss the indirect light that the depth-8 reference has: the error stops
  // at the squared bias, many times the noise at 64 spp
  for (int k = 1; k <= 2; ++k) {
    const ConvergeFit& f = r.fits[k];
    const ConvergePoint& last = r.points[5 * k + 4];
    EXPECT_TRUE(f.biased) << f.setting << ": " << f.verdict;
    EXPECT_GT(f.bias_relmse, 5 * last.noise_relmse) << f.setting;
    EXPECT_GT(f.tail_slope_spp, -0.5) << f.setting;
    EXPECT_NE(f.verdict.find("biased: error stops decreasing at ~"), std::string::npos);
  }

  // CSV: the header, then one row per setting and rung in order
  std::vector<std::string> lines = split(lucent::convergence_csv(r), '\n');
  ASSERT_EQ(lines.size(), 16u);
  EXPECT_EQ(lines[0],
            "setting,spp,seconds,samples_per_s,rmse,relmse,noise_relmse,rays_per_s,"
            "reference_noise_relmse,estimated_relmse,halves_relmse");
  const char* names[] = {"default", "max_depth=1", "max_depth=2"};
  for (size_t i = 1; i < lines.size(); ++i) {
    std::vector<std::string> f = split(lines[i], ',');
    ASSERT_EQ(f.size(), 11u) << lines[i];
    EXPECT_EQ(f[0], names[(i - 1) / 5]);
    EXPECT_EQ(std::stoi(f[1]), opt.spp_ladder[(i - 1) % 5]);
    EXPECT_GE(std::stod(f[2]), 0.0);
    EXPECT_NEAR(std::stod(f[5]), r.points[i - 1].relmse, 1e-5 * r.points[i - 1].relmse);
    EXPECT_NEAR(std::stod(f[4]), r.points[i - 1].rmse, 1e-5 * r.points[i - 1].rmse);
  }

  // SVG: well formed, one <path> per setting, the settings in the legend
  std::string svg = lucent::convergence_svg(r, "t.json & friends <test>");
  int paths = 0;
  std::string problem = check_xml(svg, "path", &paths);
  EXPECT_EQ(problem, "");
  EXPECT_EQ(paths, 3);
  for (const char* n : names)
    EXPECT_NE(svg.find(std::string(">") + n + " (slope"), std::string::npos);

  // The raster plot: the SVG's size, white background, each series drawn in its colour (sRGB
  // #1f77b4, #d62728, #2ca02c in the image's linear values)
  lucent::Image img = lucent::convergence_image(r, "t.json");
  ASSERT_EQ(img.width, 900);
  ASSERT_EQ(img.height, 500);
  EXPECT_FLOAT_EQ(img.pixel(0, 0)[0], 1.0f);
  const int srgb[3][3] = {{0x1f, 0x77, 0xb4}, {0xd6, 0x27, 0x28}, {0x2c, 0xa0, 0x2c}};
  for (const auto& c : srgb) {
    float lin[3];
    for (int k = 0; k < 3; ++k) {
      double v = c[k] / 255.0;
      lin[k] = static_cast<float>(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
    }
    int count = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const float* p = img.pixel(x, y);
        if (std::abs(p[0] - lin[0]) < 0.01f && std::abs(p[1] - lin[1]) < 0.01f &&
            std::abs(p[2] - lin[2]) < 0.01f)
          ++count;
      }
    EXPECT_GT(count, 100) << "colour " << c[0] << "," << c[1] << "," << c[2];
  }
}

// Adaptive settings on a ladder: "adaptive" renders each rung as an adaptive render of that mean
// spp (rungs below its pilot skipped), "target-error" is one adaptive render to its target
// whatever the ladder, and both refuse a time ladder.
TEST(Converge, AdaptiveAndTargetErrorSettings) {
  lucent::Scene scene =
      lucent::test::with_independent_samples(lucent::parse_scene(kScene, "t.json"));
  lucent::Scene ref_scene = scene;
  ref_scene.integrator.seed = lucent::reference_seed(scene.integrator.seed);
  lucent::RenderOptions ro;
  ro.spp = 1024;
  lucent::RenderResult reference = lucent::test::render(ref_scene, ro);

  lucent::ConvergeOptions opt;
  opt.render = lucent::test::render_options();
  opt.spp_ladder = {4, 16, 64};
  for (const char* s : {"adaptive+min-spp=8", "target-error=2e-3"})
    opt.settings.push_back(lucent::parse_converge_setting(s));
  lucent::ConvergeResult r = lucent::run_convergence(scene, reference, opt);
  ASSERT_EQ(r.points.size(), 3u);  // 16 and 64 (4 is below the pilot), and the target's one
  for (int i = 0; i < 2; ++i) {
    const ConvergePoint& p = r.points[i];
    EXPECT_EQ(p.setting, "adaptive+min-spp=8");
    EXPECT_NEAR(double(p.spp), opt.spp_ladder[i + 1], 0.1 * opt.spp_ladder[i + 1]) << i;
    EXPECT_GT(p.halves_relmse, 0.0) << "an adaptive render";
  }
  EXPECT_LT(r.points[1].relmse, 0.6 * r.points[0].relmse) << "4 times the samples";
  const ConvergePoint& t = r.points[2];
  EXPECT_EQ(t.setting, "target-error=2e-3");
  EXPECT_GT(t.halves_relmse, 0.0);
  // its error against the reference (the reference's own share taken out) within a factor 4 of
  // the target (measured 0.51 of it): Adaptive.TargetErrorIsMet measures the target itself; this
  // is the ladder's use of it
  RecordProperty("achieved_over_target",
                 std::to_string((t.relmse - t.reference_noise_relmse) / 2e-3));
  EXPECT_LT(t.relmse - t.reference_noise_relmse, 4 * 2e-3);
  EXPECT_GT(t.relmse - t.reference_noise_relmse, 2e-3 / 4);

  lucent::ConvergeOptions by_time = opt;
  by_time.spp_ladder.clear();
  by_time.time_ladder = {0.1};
  by_time.settings = {lucent::parse_converge_setting("adaptive")};
  try {
    lucent::run_convergence(scene, reference, by_time);
    ADD_FAILURE() << "an adaptive setting on a time ladder";
  } catch (const lucent::Error& e) {
    EXPECT_NE(std::string(e.what()).find("is adaptive: use an spp ladder"), std::string::npos)
        << e.what();
  }
}

// An adaptive setting skips the rungs below its pilot: with none at or above it, it rendered
// nothing and vanished from the table, the CSV and the plot (exit 0, after the reference). It is
// refused up front, naming the setting, its pilot and the largest rung.
TEST(Converge, AdaptiveSettingWithNoRungAtItsPilotIsRefused) {
  lucent::Scene scene = lucent::parse_scene(kScene, "t.json");
  scene.film.width = scene.film.height = 4;
  lucent::RenderResult reference;
  reference.mean = lucent::Image{4, 4, std::vector<float>(4 * 4 * 3, 0.5f)};
  lucent::ConvergeOptions opt;
  opt.render = lucent::test::render_options();
  opt.spp_ladder = {1, 2, 4};
  opt.settings = {lucent::parse_converge_setting("default"),
                  lucent::parse_converge_setting("adaptive+min-spp=8")};
  EXPECT_EQ(lucent::test::error_of([&] { lucent::run_convergence(scene, reference, opt); }),
            "converge: setting 'adaptive+min-spp=8' has no rung at or above its pilot of 8 spp "
            "(the ladder's largest rung is 4): add a rung of at least 8 spp or lower its min-spp");
  opt.spp_ladder = {8, 2};  // one rung at the pilot is enough, wherever it is
  EXPECT_NO_THROW(lucent::check_convergence_options(opt));

  // the command: one line, before the reference is rendered, no CSV written
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/t.json", kScene);
  lucent::test::CommandResult r = lucent::test::run_cli(
      "converge '" + dir +
      "/t.json' --width 8 --height 8 --max-spp 16 --settings adaptive --csv '" + dir + "/c.csv'");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err,
            "lucent: error: converge: setting 'adaptive' has no rung at or above its pilot of 64 "
            "spp (the ladder's largest rung is 16): add a rung of at least 64 spp or lower its "
            "min-spp\n");
  EXPECT_EQ(r.out, "");
  EXPECT_FALSE(std::filesystem::exists(dir + "/c.csv"));
}

// "time to relMSE": a setting already below the common error at its first rung (a target-error
// setting is one render, here far below the uniform ladder's last error) reached it sooner than
// that rung's time, which only bounds it: it is printed as a bound ("<="), not as the time to the
// error (it was "x3.71 of default" for a render 3.6 times below it).
TEST(Converge, TimeToTheErrorOfASettingBelowItAtItsFirstRungIsABound) {
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/t.json", kScene);
  lucent::test::CommandResult r = lucent::test::run_cli(
      "converge '" + dir +
      "/t.json' --width 8 --height 8 --spp-ladder 1,2 --reference-spp 256 --settings "
      "default,target-error=1e-3+min-spp=8");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(
      std::regex_search(r.out, std::regex("\n  default +[0-9.]+ s  \\(x1.00 of default\\)\n")))
      << r.out;
  EXPECT_TRUE(std::regex_search(
      r.out, std::regex("\n  target-error=1e-3\\+min-spp=8 +<= [0-9.]+ s  \\(x<=[0-9.]+ of "
                        "default; already below it at its first rung\\)\n")))
      << r.out;

  // the bound as the first setting, the one the others are measured against: their ratios are
  // lower bounds (they were printed as values, "x0.22 of target-error=..." for a setting at least
  // 0.22 times as slow), and its own is 1 (it read "x<=1.00")
  r = lucent::test::run_cli("converge '" + dir +
                            "/t.json' --width 8 --height 8 --spp-ladder 1,2 --reference-spp 256 "
                            "--settings target-error=1e-3+min-spp=8,default");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::regex_search(
      r.out, std::regex("\n  target-error=1e-3\\+min-spp=8 +<= [0-9.]+ s  \\(x1.00 of "
                        "target-error=1e-3\\+min-spp=8; already below it at its first rung\\)\n")))
      << r.out;
  EXPECT_TRUE(std::regex_search(
      r.out,
      std::regex("\n  default +[0-9.]+ s  \\(x>=[0-9.]+ of target-error=1e-3\\+min-spp=8\\)\n")))
      << r.out;
}

// Standard output closed early (`converge ... | head`): the table's write fails, and the CSV and
// the plots are written all the same, with one line and status 1 (SIGPIPE killed the study
// there, its files never written, with no line and status 141).
TEST(Converge, AClosedPipeOnStandardOutputLosesNoFile) {
  const std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/t.json", R"({
    "film": {"width": 8, "height": 8},
    "integrator": {"type": "path", "max_depth": 2},
    "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [{"type": "sphere", "center": [0, 0, -3], "radius": 1, "material": "m"}],
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}]
  })");
  const std::string err = dir + "/err", status = dir + "/status";
  const std::string cmd = "('" + std::string(LUCENT_CLI_PATH) + "' converge '" + dir +
                          "/t.json' --spp-ladder 1,2 --reference-spp 16 --csv '" + dir +
                          "/c.csv' --plot '" + dir + "/c.svg' 2>'" + err + "'; echo $? >'" +
                          status + "') | head -c 0";
  lucent::test::write_file(dir + "/pipe.sh", cmd + "\n");
  ASSERT_EQ(std::system(("bash '" + dir + "/pipe.sh'").c_str()), 0);
  const std::string text = read_file(err);
  EXPECT_EQ(read_file(status), "1\n") << text;
  EXPECT_NE(text.find("lucent: error: standard output: cannot write (Broken pipe)"),
            std::string::npos)
      << text;
  EXPECT_TRUE(std::filesystem::exists(dir + "/c.csv")) << text;
  EXPECT_TRUE(std::filesystem::exists(dir + "/c.svg")) << text;
}

// A setting whose knob the integrator it renders with does not read changes nothing, and the
// study reported it as if it did (clamp=1 on a whitted scene: "x0.53 of default", noise): it is
// refused, by the library and by the command before the reference is rendered; the same knob
// with integrator=path is a real setting.
TEST(Converge, SettingsTheIntegratorIgnoresAreRefused) {
  lucent::Scene scene = lucent::parse_scene(kScene, "t.json");
  scene.film.width = scene.film.height = 4;
  scene.integrator.type = lucent::IntegratorType::Whitted;
  lucent::RenderResult reference;
  reference.mean = lucent::Image{4, 4, std::vector<float>(4 * 4 * 3, 0.5f)};
  lucent::ConvergeOptions opt;
  opt.render = lucent::test::render_options();
  opt.spp_ladder = {1, 2};
  const std::pair<const char*, const char*> cases[] = {
      {"clamp=1", "clamp: only the path integrator has it, and the setting renders with whitted"},
      {"no-mis", "mis: only the path integrator has it, and the setting renders with whitted"},
      {"splits=0", "splits: only the path integrator has it, and the setting renders with whitted"},
      {"rr_depth=2",
       "rr_depth: only the path integrator has it, and the setting renders with whitted"},
      {"integrator=direct+max_depth=2",
       "max_depth: only the path and whitted integrators have it, and the setting renders with "
       "direct"}};
  for (const auto& [text, why] : cases) {
    opt.settings = {lucent::parse_converge_setting("default"),
                    lucent::parse_converge_setting(text)};
    EXPECT_EQ(lucent::test::error_of([&] { lucent::run_convergence(scene, reference, opt); }),
              std::string("converge: setting '") + text + "': " + why);
  }
  opt.settings = {lucent::parse_converge_setting("max_depth=2"),
                  lucent::parse_converge_setting("integrator=path+clamp=1+no-mis"),
                  lucent::parse_converge_setting("no-caustics")};  // as render --no-caustics
  EXPECT_NO_THROW(lucent::check_convergence_options(opt, &scene));

  // the command: one line, before the reference is rendered, no CSV written
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/t.json", kScene);
  lucent::test::CommandResult r = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --width 8 --height 8 --max-spp 2 --settings " +
      "integrator=albedo+clamp=1 --csv '" + dir + "/c.csv'");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err,
            "lucent: error: converge: setting 'integrator=albedo+clamp=1': clamp: only the path "
            "integrator has it, and the setting renders with albedo\n");
  EXPECT_FALSE(std::filesystem::exists(dir + "/c.csv"));
}

/// A kernel render of `scene` at reference_seed(): independent of the ladder's samples.
lucent::RenderResult independent_reference(const lucent::Scene& scene) {
  lucent::Scene ref_scene = scene;
  ref_scene.integrator.seed = lucent::reference_seed(scene.integrator.seed);
  return lucent::test::render(ref_scene, lucent::test::render_options());
}

// The rungs are taken in ascending order, whatever order the ladder gives them in: the verdict
// reads the last point as the largest rung and the fit the last three (a ladder 1024,4,8 was
// judged at 8 spp, "unbiased" for a clamp judged biased on 4,8,1024), and the plot joined the
// points in the order given.
TEST(Converge, RungsAreTakenInAscendingOrder) {
  lucent::Scene scene =
      lucent::test::with_independent_samples(lucent::parse_scene(kScene, "t.json"));
  scene.film.width = scene.film.height = 8;
  const lucent::RenderResult reference = independent_reference(scene);
  lucent::ConvergeOptions opt;
  opt.render = lucent::test::render_options();
  opt.spp_ladder = {16, 2, 4};
  lucent::ConvergeResult given = lucent::run_convergence(scene, reference, opt);
  opt.spp_ladder = {2, 4, 16};
  lucent::ConvergeResult sorted = lucent::run_convergence(scene, reference, opt);
  ASSERT_EQ(given.points.size(), 3u);
  ASSERT_EQ(sorted.points.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(given.points[i].spp, opt.spp_ladder[i]) << i;
    EXPECT_EQ(given.points[i].relmse, sorted.points[i].relmse) << i;
  }
  ASSERT_EQ(given.fits.size(), 1u);
  EXPECT_EQ(given.fits[0].verdict, sorted.fits[0].verdict);
  EXPECT_EQ(given.fits[0].slope_spp, sorted.fits[0].slope_spp);
}

// The options are checked before the rungs are sorted: a NaN rung given to the library broke
// std::sort's ordering (undefined behaviour; past 16 rungs libstdc++'s insertion sort may read
// out of bounds, which the sanitizer build would report).
TEST(Converge, ANanRungIsRefusedBeforeSorting) {
  lucent::Scene scene = lucent::parse_scene(kScene, "t.json");
  scene.film.width = scene.film.height = 4;
  lucent::RenderResult reference;
  reference.mean = lucent::Image{4, 4, std::vector<float>(48, 0.5f)};
  lucent::ConvergeOptions opt;
  opt.render = lucent::test::render_options();
  for (int i = 0; i < 40; ++i)
    opt.time_ladder.push_back(i % 5 == 0 ? std::nan("") : 0.001 * (40 - i));
  EXPECT_EQ(lucent::test::error_of([&] {
              lucent::run_convergence(scene, reference, opt);
            }).rfind("converge: time ladder values must be in (0, 1e7] seconds, got nan", 0),
            0u);
}

// A lucent render at the ladder's own seed holds the rungs' own samples and hides their error:
// `lucent converge` refused such a --reference, but run_convergence (and so Python's converge)
// took it, and an unbiased ladder measured relMSE ~0.6x its noise against it. Refused by the
// library too; an image without the key of its random numbers (arrays, a PFM) is taken.
TEST(Converge, ReferenceAtTheLaddersSeedIsRefused) {
  lucent::Scene scene = lucent::parse_scene(kScene, "t.json");
  scene.film.width = scene.film.height = 8;
  lucent::RenderResult same = lucent::test::render(scene, lucent::test::render_options());
  ASSERT_EQ(same.seed, 3u);
  ASSERT_FALSE(same.sampler.empty());
  lucent::ConvergeOptions opt;
  opt.render = lucent::test::render_options();
  opt.spp_ladder = {1};
  EXPECT_EQ(lucent::test::error_of([&] { lucent::run_convergence(scene, same, opt); }),
            "the reference image was rendered with seed 3, the ladder's: its samples include the "
            "rungs' own, which would hide their error; render it with another seed "
            "(lucent::reference_seed)");
  lucent::RenderResult plain;
  plain.mean = same.mean;
  EXPECT_EQ(lucent::run_convergence(scene, plain, opt).points.size(), 1u);
  EXPECT_EQ(lucent::run_convergence(scene, independent_reference(scene), opt).points.size(), 1u);
}

// A ladder 8,4: an adaptive setting continued the 8-spp render for the 4-spp rung, and reported
// 8 spp twice. The rungs are now taken in ascending order (Converge.RungsAreTakenInAscendingOrder),
// adaptive ones too: the 4-spp rung comes first and is the render of a ladder of that rung alone,
// for each setting.
TEST(Converge, AdaptiveLadderGivenDescendingRendersAscending) {
  lucent::Scene scene = lucent::parse_scene(kScene, "t.json");
  scene.film.width = scene.film.height = 8;
  const lucent::RenderResult reference = independent_reference(scene);
  lucent::ConvergeOptions opt;
  opt.render = lucent::test::render_options();
  opt.spp_ladder = {8, 4};
  opt.settings = {lucent::parse_converge_setting("adaptive+min-spp=4"),
                  lucent::parse_converge_setting("default")};
  const lucent::ConvergeResult r = lucent::run_convergence(scene, reference, opt);
  ASSERT_EQ(r.points.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ(r.points[i].spp, i % 2 ? 8u : 4u) << i;
  opt.spp_ladder = {4};
  const lucent::ConvergeResult alone = lucent::run_convergence(scene, reference, opt);
  ASSERT_EQ(alone.points.size(), 2u);
  EXPECT_EQ(r.points[0].relmse, alone.points[0].relmse);
  EXPECT_EQ(r.points[2].relmse, alone.points[1].relmse);
  EXPECT_NE(r.points[0].relmse, r.points[1].relmse);
}

// A study renders every rung on one session: an on_point that changed it (set_scene, render,
// reset) was taken, and the study measured the other scene's error against the reference without
// a word (relMSE 0.015 then 36.7, "biased"; the API tester's find). Refused now, naming on_point;
// reading the session and cancel() still work there.
TEST(Converge, OnPointCannotChangeTheStudysSession) {
  lucent::Scene scene = lucent::parse_scene(kScene, "t.json");
  scene.film.width = scene.film.height = 8;
  const lucent::RenderResult reference = independent_reference(scene);
  lucent::Renderer session(lucent::test::session_options());
  lucent::ConvergeOptions opt;
  opt.render = lucent::test::render_options();
  opt.renderer = &session;
  opt.spp_ladder = {1, 2, 4};
  lucent::Scene other = scene;
  other.lights[0].intensity *= 10.0;
  const std::function<void(lucent::Renderer&)> changes[] = {
      [&](lucent::Renderer& r) { r.set_scene(other); },
      [](lucent::Renderer& r) { r.render(3); },
      [](lucent::Renderer& r) { r.reset(); },
  };
  for (const auto& change : changes) {
    int points = 0;
    opt.on_point = [&](const ConvergePoint&) {
      ++points;
      EXPECT_GT(session.spp(), 0u);  // reads work
      change(session);
    };
    const std::string error =
        lucent::test::error_of([&] { lucent::run_convergence(scene, reference, opt); });
    EXPECT_NE(error.find(": cannot change the session while run_convergence's on_point runs, "
                         "which holds it"),
              std::string::npos)
        << error;
    EXPECT_EQ(points, 1);
  }
  // and the session is free again afterwards
  session.set_scene(scene);
  session.render(1);
}

// A study on the caller's session: its cancel flag is the study's while it runs and the session's
// own afterwards (the session once kept a pointer to the study's flag, which the caller may
// destroy on return), and without a study flag the session's own stops the study.
TEST(Converge, CallersSessionGetsItsCancelFlagBack) {
  lucent::Scene scene = lucent::parse_scene(kScene, "t.json");
  scene.film.width = scene.film.height = 8;
  lucent::RenderResult reference = independent_reference(scene);
  lucent::Renderer session(lucent::test::session_options());
  std::atomic<bool> own{false};
  session.set_cancel_flag(&own);
  lucent::ConvergeOptions opt;
  opt.render = lucent::test::render_options();
  opt.spp_ladder = {1, 2};
  opt.renderer = &session;
  {
    std::atomic<bool> study{false};
    opt.render.cancel = &study;
    opt.on_point = [&](const ConvergePoint&) { EXPECT_EQ(session.cancel_flag(), &study); };
    EXPECT_EQ(lucent::run_convergence(scene, reference, opt).points.size(), 2u);
  }
  EXPECT_EQ(session.cancel_flag(), &own);
  opt.render.cancel = nullptr;
  opt.on_point = [&](const ConvergePoint&) { own = true; };  // stops after the first rung
  EXPECT_EQ(lucent::run_convergence(scene, reference, opt).points.size(), 1u);
  EXPECT_EQ(session.cancel_flag(), &own);
}

// The caller's session's cancel() between two rungs stops the study, as its cancel flag does:
// each rung's render call cleared a cancel asked for before it began, so one asked for from
// on_point (or from another thread while a rung was compared, or a setting's kernel built) was
// forgotten and the ladder went on. What was rendered stays in the session, and the session's
// next render is not cancelled.
TEST(Converge, CallersSessionsCancelBetweenRungsStopsTheStudy) {
  lucent::Scene scene = lucent::parse_scene(kScene, "t.json");
  scene.film.width = scene.film.height = 8;
  lucent::RenderResult reference = independent_reference(scene);
  lucent::Renderer session(lucent::test::session_options());
  lucent::ConvergeOptions opt;
  opt.render = lucent::test::render_options();
  opt.spp_ladder = {1, 2, 4};
  opt.settings = {lucent::parse_converge_setting("default"),
                  lucent::parse_converge_setting("max_depth=1")};
  opt.renderer = &session;
  int points = 0;
  opt.on_point = [&](const ConvergePoint&) {
    if (++points == 1) session.cancel();  // after the first rung
  };
  lucent::ConvergeResult r = lucent::run_convergence(scene, reference, opt);
  EXPECT_EQ(r.points.size(), 1u);
  EXPECT_EQ(points, 1);
  EXPECT_EQ(session.spp(), 1u) << "the first rung's samples, no more";
  session.render(1);
  EXPECT_FALSE(session.result().cancelled);

  // after a setting's last rung: the next setting is not rendered
  points = 0;
  opt.on_point = [&](const ConvergePoint&) {
    if (++points == 3) session.cancel();
  };
  r = lucent::run_convergence(scene, reference, opt);
  ASSERT_EQ(r.points.size(), 3u);
  EXPECT_EQ(r.fits.size(), 1u);
  EXPECT_EQ(r.points.back().setting, "default");
  EXPECT_EQ(session.result().spp, 4u);

  // a cancel asked for before the study is not the study's
  session.cancel();
  opt.on_point = nullptr;
  EXPECT_EQ(lucent::run_convergence(scene, reference, opt).points.size(), 6u);
}

// run_convergence on a session busy with a render (another thread's, or the study started from
// that render's own on_progress) is refused before it changes anything: it cleared the render's
// pending cancel() (its CancelScope began) and swapped in the study's cancel flag, then failed at
// set_build_options, and the render ran on for its whole budget (the API tester's find).
TEST(Converge, RefusedOnABusySessionKeepsTheRendersCancel) {
  lucent::Scene scene = lucent::parse_scene(kScene, "t.json");
  scene.film.width = scene.film.height = 8;
  const lucent::RenderResult reference = independent_reference(scene);
  lucent::Renderer session(lucent::test::session_options());
  session.set_scene(scene);
  lucent::ConvergeOptions opt;
  opt.render = lucent::test::render_options();
  opt.spp_ladder = {1};
  opt.renderer = &session;
  std::atomic<bool> study_flag{false};
  opt.render.cancel = &study_flag;
  const std::string refused = "run_convergence: a render of this session is in progress";
  const std::uint64_t budget = 1000000;
  // from the render's own on_progress, after its cancel()
  int passes = 0;
  std::string error;
  session.render(budget, [&](const lucent::RenderProgress&) {
    if (++passes == 1) {
      session.cancel();
      error = lucent::test::error_of([&] { lucent::run_convergence(scene, reference, opt); });
      EXPECT_EQ(session.cancel_flag(), nullptr) << "the study's flag was left in place";
    }
    if (passes == 3) session.cancel();  // (where the cancel was lost: ends the render)
  });
  EXPECT_EQ(error.find(refused), 0u) << error;
  EXPECT_LT(passes, 3) << "the render went on after its cancel()";
  EXPECT_LT(session.spp(), budget);
  EXPECT_TRUE(session.result().cancelled);

  // another thread's render, held in its on_progress while the study is refused
  session.reset();
  passes = 0;
  error.clear();
  std::atomic<bool> started{false}, released{false};
  std::thread render([&] {
    session.render(budget, [&](const lucent::RenderProgress&) {
      if (++passes == 1) {
        started = true;
        while (!released) std::this_thread::yield();
      }
      if (passes == 3) session.cancel();
    });
  });
  while (!started) std::this_thread::yield();
  session.cancel();
  error = lucent::test::error_of([&] { lucent::run_convergence(scene, reference, opt); });
  released = true;
  render.join();
  EXPECT_EQ(error.find(refused), 0u) << error;
  EXPECT_LT(passes, 3) << "the render went on after its cancel()";
  EXPECT_TRUE(session.result().cancelled);
  EXPECT_EQ(session.cancel_flag(), nullptr);

  // and the session takes a study once free
  study_flag = false;
  EXPECT_EQ(lucent::run_convergence(scene, reference, opt).points.size(), 1u);
  EXPECT_EQ(session.cancel_flag(), nullptr);
}

TEST(Converge, XmlCheckerRejectsMalformedDocuments) {
  int n = 0;
  EXPECT_EQ(check_xml("<svg><path d=\"M0 0\"/></svg>", "path", &n), "");
  EXPECT_EQ(n, 1);
  EXPECT_NE(check_xml("<svg><g></svg>", "path", &n), "");
  EXPECT_NE(check_xml("<svg><path d=M0/></svg>", "path", &n), "");
  EXPECT_NE(check_xml("<svg>a & b</svg>", "path", &n), "");
  EXPECT_NE(check_xml("<svg/><svg/>", "path", &n), "");
  EXPECT_EQ(check_xml("<svg>\t\xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80\xef\xbf\xbd</svg>", "path", &n),
            "");
  for (const char* bad :
       {"<svg>\x01</svg>", "<svg>\xff</svg>", "<svg>\xc3</svg>", "<svg>\xc0\xaf</svg>",
        "<svg>\xed\xa0\x80</svg>", "<svg>\xef\xbf\xbe</svg>", "<svg a=\"\x1b\"/>"})
    EXPECT_NE(check_xml(bad, "path", &n), "") << bad;
}

// The plot's title (the scene's file name, which may hold any bytes), legend and labels are
// valid XML 1.0 in UTF-8 whatever their bytes: a control byte or one that is not UTF-8 made the
// SVG ill-formed (browsers refused it). They are written as \xNN, as the command line shows names.
TEST(Converge, SvgOfAnyTitleIsValidXml) {
  EXPECT_EQ(lucent::plot::xml_escape("a\x01"
                                     "b\xff<&>\"' \xc3\xa9\t\x7f\xef\xbf\xbf\xef\xbf\xbd"),
            "a\\x01b\\xff&lt;&amp;&gt;&quot;&apos; \xc3\xa9\\t\\x7f\\xef\\xbf\\xbf\xef\xbf\xbd");
  lucent::ConvergeResult r;
  r.points = synthetic({1e-2, 5e-3}, {1e-2, 5e-3});
  r.points[0].setting = r.points[1].setting = "s\x02\xfe";
  r.fits.push_back(lucent::fit_convergence(r.points));
  // a NUL too: a file name cannot hold one, a Python title can
  const std::string title = std::string(
                                "a\x01"
                                "b\xff.json\x1b[31m \xed\xa0\x80\xef\xbf\xbe") +
                            '\0' + ", 16x16";
  const std::string svg = lucent::convergence_svg(r, title);
  int paths = 0;
  EXPECT_EQ(check_xml(svg, "path", &paths), "") << svg;
  EXPECT_EQ(paths, 1);
  EXPECT_NE(svg.find("a\\x01b\\xff.json\\x1b[31m \\xed\\xa0\\x80\\xef\\xbf\\xbe\\x00, 16x16"),
            std::string::npos)
      << svg;
  EXPECT_NE(svg.find("s\\x02\\xfe"), std::string::npos) << svg;
}

TEST(Converge, CommandWritesCsvAndPlot) {
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/t.json", kScene);
  lucent::test::CommandResult r = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --spp-ladder 2,4,8 --reference-spp 256 --settings " +
      "default,max_depth=1 --csv '" + dir + "/c.csv' --plot '" + dir +
      "/c.svg' --save-reference '" + dir + "/ref.exr'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("max_depth=1"), std::string::npos);
  EXPECT_NE(r.out.find("biased: error stops decreasing"), std::string::npos) << r.out;
  std::vector<std::string> csv = split(read_file(dir + "/c.csv"), '\n');
  EXPECT_EQ(csv.size(), 7u);
  int paths = 0;
  EXPECT_EQ(check_xml(read_file(dir + "/c.svg"), "path", &paths), "");
  EXPECT_EQ(paths, 2);

  // the saved reference is reused: same size, so it is accepted
  lucent::test::CommandResult again = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --spp-ladder 2 -q --reference '" + dir + "/ref.exr'");
  EXPECT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(lucent::test::count_lines(again.err), 0) << again.err;
  // one rung: no slope to print (it printed 0.00)
  EXPECT_NE(again.out.find("  default                   n/a  (against spp   n/a, last 1 rung   "
                           "n/a)  unbiased"),
            std::string::npos)
      << again.out;
}

TEST(Converge, CommandTimeLadderAndCpuReference) {
  // The kernel against the independent reference integrator: the same expected image, so the
  // error is noise (error/noise near 1, "unbiased"); a time ladder gives one row per budget.
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/t.json", kScene);
  lucent::test::CommandResult r = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --time-ladder 0.01,0.03 --reference-cpu " +
      "--reference-spp 1024 --csv '" + dir + "/c.csv' --plot '" + dir + "/c.png' --plot '" + dir +
      "/c.svg'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("with the reference integrator"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("unbiased (error/noise"), std::string::npos) << r.out;
  lucent::Image png = lucent::read_image(dir + "/c.png");
  EXPECT_EQ(png.width, 900);
  EXPECT_EQ(png.height, 500);
  int paths = 0;
  EXPECT_EQ(check_xml(read_file(dir + "/c.svg"), "path", &paths), "");
  EXPECT_EQ(paths, 1);
  std::vector<std::string> csv = split(read_file(dir + "/c.csv"), '\n');
  ASSERT_EQ(csv.size(), 3u);
  for (size_t i = 1; i < csv.size(); ++i) {
    std::vector<std::string> f = split(csv[i], ',');
    ASSERT_EQ(f.size(), 11u);
    EXPECT_EQ(f[0], "default");
    EXPECT_GE(std::stoi(f[1]), 1);
  }
}

TEST(Converge, CommandErrors) {
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/t.json", kScene);
  lucent::test::CommandResult bad = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --settings default,bogus --spp-ladder 2");
  EXPECT_EQ(bad.status, 1);
  EXPECT_EQ(lucent::test::count_lines(bad.err), 1) << bad.err;
  EXPECT_NE(bad.err.find("bogus"), std::string::npos) << bad.err;

  lucent::test::CommandResult twice = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --settings default,default --spp-ladder 2");
  EXPECT_EQ(twice.status, 1);
  EXPECT_NE(twice.err.find("twice"), std::string::npos) << twice.err;
  // the same setting in two spellings rendered twice
  lucent::test::CommandResult spelt = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --settings max_depth=3,max-depth=3 --spp-ladder 2");
  EXPECT_EQ(spelt.status, 1);
  EXPECT_EQ(spelt.err,
            "lucent: error: --settings: 'max-depth=3' is the same setting as 'max_depth=3'\n");
  spelt = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --settings clamp=1+no-mis,no_mis+clamp=1.0 --spp-ladder 2");
  EXPECT_EQ(spelt.status, 1);
  EXPECT_NE(spelt.err.find("'no_mis+clamp=1.0' is the same setting as 'clamp=1+no-mis'"),
            std::string::npos)
      << spelt.err;

  // a reference of another size names the file
  lucent::test::CommandResult size = lucent::test::run_cli(
      "converge '" + dir +
      "/t.json' --width 16 --spp-ladder 2 --reference-spp 4 --save-reference '" + dir +
      "/small.exr'");
  ASSERT_EQ(size.status, 0) << size.err;
  lucent::test::CommandResult mismatch = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --spp-ladder 2 --reference '" + dir + "/small.exr'");
  EXPECT_EQ(mismatch.status, 1);
  EXPECT_EQ(lucent::test::count_lines(mismatch.err), 1) << mismatch.err;
  EXPECT_NE(mismatch.err.find("small.exr: size 16x24 differs"), std::string::npos) << mismatch.err;

  // a display image (8-bit PNG of the scene, the right size) is no reference: its values are
  // tone-mapped and clipped (it was accepted, and the slopes came out at +13)
  lucent::test::CommandResult png =
      lucent::test::run_cli("render '" + dir + "/t.json' -q -o '" + dir + "/ref.png' --spp 4");
  ASSERT_EQ(png.status, 0) << png.err;
  lucent::test::CommandResult display = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --spp-ladder 2 --reference '" + dir + "/ref.png'");
  EXPECT_EQ(display.status, 1);
  EXPECT_EQ(display.err, "lucent: error: " + dir +
                             "/ref.png: a PNG image holds display values (tone-mapped, clipped), "
                             "not radiance: give a .exr, .pfm or .hdr reference (lucent render "
                             "SCENE --seed S -o ref.exr, S not the scene's seed)\n");

  // a reference rendered at the scene's own seed replays the rungs' samples: refused; at another
  // seed it serves (lucent render writes the seed into its EXRs)
  ASSERT_EQ(
      lucent::test::run_cli("render '" + dir + "/t.json' -q --spp 8 -o '" + dir + "/same.exr'")
          .status,
      0);
  lucent::test::CommandResult same = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --spp-ladder 2 -q --reference '" + dir + "/same.exr'");
  EXPECT_EQ(same.status, 1);
  EXPECT_EQ(same.err,
            "lucent: error: " + dir +
                "/same.exr: rendered with seed 3, the ladder's: its samples include "
                "the rungs' own, which would hide their error; render it with another "
                "--seed, or let converge render it (--reference-spp, --save-reference)\n");
  ASSERT_EQ(lucent::test::run_cli("render '" + dir + "/t.json' -q --spp 8 --seed 7 -o '" + dir +
                                  "/other.exr'")
                .status,
            0);
  lucent::test::CommandResult other = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --spp-ladder 2 -q --reference '" + dir + "/other.exr'");
  EXPECT_EQ(other.status, 0) << other.err;

  lucent::test::CommandResult pdf = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --spp-ladder 2 --plot '" + dir + "/p.pdf'");
  EXPECT_EQ(pdf.status, 1);
  EXPECT_NE(pdf.err.find("p.pdf: unknown plot format '.pdf' (use .svg or .png)"), std::string::npos)
      << pdf.err;

  lucent::test::CommandResult both =
      lucent::test::run_cli("converge '" + dir + "/t.json' --reference x.exr --reference-cpu");
  EXPECT_EQ(both.status, 2);
  // --max-spp makes the default ladder: with a ladder given it was ignored without a word
  for (const char* ladder : {"--spp-ladder 2", "--time-ladder 0.01"}) {
    lucent::test::CommandResult max = lucent::test::run_cli(
        "converge '" + dir + "/t.json' --max-spp 4 -q --reference-spp 4 " + ladder);
    EXPECT_EQ(max.status, 2) << ladder << "\n" << max.out;
    EXPECT_EQ(lucent::test::count_lines(max.err), 1) << max.err;
    EXPECT_NE(max.err.find("excludes --max-spp"), std::string::npos) << max.err;
  }
}

// The outputs (--csv, every --plot, --save-reference) never overwrite an input (the scene, the
// --reference image, a texture, an OBJ file or an MTL library of the scene) nor each other, and
// are checked before anything renders: one line, exit 1, every file as it was. (--csv on the
// --reference image replaced it with CSV text, exit 0; --csv and --plot on one file kept only the
// plot; --csv on an MTL library replaced it.)
TEST(Converge, CommandOutputsOverwriteNoInputAndNoOtherOutput) {
  const std::string dir = lucent::test::temp_dir();
  auto q = [](const std::string& s) { return "'" + s + "'"; };
  lucent::write_image(dir + "/tex.png", lucent::Image{2, 2, std::vector<float>(12, 0.5f)});
  lucent::test::write_file(dir + "/m.obj", "v -1 -1 -2\nv 1 -1 -2\nv 0 1 -2\nf 1 2 3\n");
  lucent::test::write_file(dir + "/lib.obj",
                           "mtllib lib.mtl\nv -1 1 -2\nv 1 1 -2\nv 0 2 -2\nusemtl a\nf 1 2 3\n");
  lucent::test::write_file(dir + "/lib.mtl", "newmtl a\nKd 0.5 0.25 0.125\n");
  lucent::test::write_file(dir + "/t.json", R"({
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 45},
    "film": {"width": 8, "height": 8},
    "integrator": {"type": "path", "max_depth": 2, "seed": 3},
    "materials": {"t": {"type": "diffuse", "albedo": {"texture": "tex.png"}}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "t"},
               {"type": "mesh", "file": "m.obj", "material": "t"},
               {"type": "mesh", "file": "lib.obj"}],
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}]
  })");
  const std::string scene = q(dir + "/t.json");
  ASSERT_EQ(
      lucent::test::run_cli("render " + scene + " -q --spp 4 --seed 7 -o " + q(dir + "/ref.exr"))
          .status,
      0);
  const std::string files[] = {"t.json", "ref.exr", "tex.png", "m.obj", "lib.obj", "lib.mtl"};
  std::vector<std::string> before;
  for (const std::string& f : files) before.push_back(read_file(dir + "/" + f));
  auto error = [&](const std::string& args) {
    lucent::test::CommandResult r =
        lucent::test::run_cli("converge " + scene + " --spp-ladder 1,2 " + args);
    EXPECT_EQ(r.status, 1) << args << ": " << r.out << r.err;
    EXPECT_EQ(lucent::test::count_lines(r.err), 1) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    return r.err;
  };
  const std::string ref = " --reference " + q(dir + "/ref.exr");
  EXPECT_EQ(
      error(ref + " --csv " + q(dir + "/ref.exr")),
      "lucent: error: " + dir + "/ref.exr: is the --reference image; refusing to overwrite it\n");
  EXPECT_EQ(error(ref + " --csv " + q(dir + "/./t.json")),
            "lucent: error: " + dir + "/./t.json: is the scene file; refusing to overwrite it\n");
  EXPECT_EQ(error("--reference-spp 4 --plot " + q(dir + "/tex.png")),
            "lucent: error: " + dir + "/tex.png: is an input of the scene (" + dir +
                "/tex.png); refusing to overwrite it\n");
  EXPECT_EQ(error("--reference-spp 4 --csv " + q(dir + "/m.obj")),
            "lucent: error: " + dir + "/m.obj: is an input of the scene (" + dir +
                "/m.obj); refusing to overwrite it\n");
  EXPECT_EQ(error("--reference-spp 4 --csv " + q(dir + "/lib.mtl")),
            "lucent: error: " + dir + "/lib.mtl: is an input of the scene (" + dir +
                "/lib.mtl); refusing to overwrite it\n");
  EXPECT_EQ(error("--reference-spp 4 --save-reference " + q(dir + "/ref.exr") + " --csv " +
                  q(dir + "/ref.exr")),
            "lucent: error: " + dir +
                "/ref.exr: given as --csv and as --save-reference; give "
                "each output its own file\n");
  EXPECT_EQ(error(ref + " --csv " + q(dir + "/c.svg") + " --plot " + q(dir + "/./c.svg")),
            "lucent: error: " + dir +
                "/./c.svg: given as --csv and as --plot; give each output "
                "its own file\n");
  EXPECT_EQ(error(ref + " --plot " + q(dir + "/p.svg") + " --plot " + q(dir + "/p.svg")),
            "lucent: error: " + dir +
                "/p.svg: given as --plot and as --plot; give each output "
                "its own file\n");
  // a FIFO (its open waited for a reader for ever) and a device (refused by the write, after
  // the whole study): refused before rendering, as `render -o` refuses them
  for (const char* option : {"--csv", "--plot", "--save-reference"}) {
    const std::string fifo = dir + "/fifo" +
                             (option[2] == 'c'   ? ".csv"
                              : option[2] == 'p' ? ".svg"
                                                 : ".exr");
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
    EXPECT_EQ(error("--reference-spp 4 " + std::string(option) + " " + q(fifo)),
              "lucent: error: " + fifo +
                  ": is a pipe, not a regular file (outputs are written to a temporary file "
                  "renamed into place)\n");
  }
  EXPECT_EQ(error("--reference-spp 4 --csv /dev/full"),
            "lucent: error: /dev/full: is a device, not a regular file (outputs are written to a "
            "temporary file renamed into place)\n");
  for (size_t k = 0; k < before.size(); ++k)
    EXPECT_EQ(read_file(dir + "/" + files[k]), before[k]) << files[k] << " was overwritten";
  for (const char* f : {"/c.svg", "/p.svg"}) EXPECT_FALSE(std::filesystem::exists(dir + f)) << f;

  // --save-reference saves a reference converge renders: with --reference it saved nothing,
  // silently; and it writes OpenEXR, which went into a .png file
  lucent::test::CommandResult both = lucent::test::run_cli(
      "converge " + scene + " --spp-ladder 1" + ref + " --save-reference " + q(dir + "/never.exr"));
  EXPECT_EQ(both.status, 2) << both.out << both.err;
  EXPECT_EQ(lucent::test::count_lines(both.err), 1) << both.err;
  EXPECT_NE(both.err.find("--reference excludes --save-reference"), std::string::npos) << both.err;
  EXPECT_EQ(
      error("--reference-spp 4 --save-reference " + q(dir + "/sr.png")),
      "lucent: error: " + dir + "/sr.png: --save-reference writes OpenEXR: use an .exr file\n");
  for (const char* f : {"/never.exr", "/sr.png"})
    EXPECT_FALSE(std::filesystem::exists(dir + f)) << f;

  // the outputs that are their own files are still written, the reference saved as EXR
  lucent::test::CommandResult ok = lucent::test::run_cli(
      "converge " + scene + " --spp-ladder 1,2 -q --reference-spp 4 --csv " + q(dir + "/c.csv") +
      " --plot " + q(dir + "/c.svg") + " --save-reference " + q(dir + "/sr.EXR"));
  ASSERT_EQ(ok.status, 0) << ok.err;
  EXPECT_EQ(split(read_file(dir + "/c.csv"), '\n').size(), 3u);
  EXPECT_EQ(lucent::read_render(dir + "/sr.EXR").samples.size(), 64u);
}

// A reference holding a NaN or an infinity made every error NaN, and converge printed a
// confident verdict with exit 0: refused, naming the file, the pixel and the channel.
TEST(Converge, NonFiniteReferenceIsRefused) {
  const std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/t.json", kScene);
  for (const auto& [k, value, what] :
       {std::tuple<size_t, float, const char*>{(1 * 8 + 2) * 3 + 1, NAN,
                                               "(2, 1) channel G is "
                                               "not finite (nan)"},
        std::tuple<size_t, float, const char*>{(7 * 8 + 5) * 3 + 2, -INFINITY,
                                               "(5, 7) channel B is not finite (-inf)"}}) {
    lucent::Image img{8, 8, std::vector<float>(8 * 8 * 3, 0.5f)};
    img.rgb[k] = value;
    lucent::write_image(dir + "/bad.pfm", img);
    lucent::test::CommandResult r =
        lucent::test::run_cli("converge '" + dir +
                              "/t.json' --width 8 --height 8 --spp-ladder 1 "
                              "--reference '" +
                              dir + "/bad.pfm'");
    EXPECT_EQ(r.status, 1) << r.out << r.err;
    EXPECT_EQ(r.err, "lucent: error: " + dir + "/bad.pfm: pixel " + what + "\n");
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  // and in a variance layer
  lucent::RenderResult v;
  v.mean = lucent::Image{8, 8, std::vector<float>(8 * 8 * 3, 0.5f)};
  v.variance = lucent::Image{8, 8, std::vector<float>(8 * 8 * 3, 0.1f)};
  v.samples.assign(64, 16);
  v.variance.rgb[3] = INFINITY;
  lucent::write_render_exr(dir + "/var.exr", v);
  lucent::test::CommandResult r = lucent::test::run_cli(
      "converge '" + dir + "/t.json' --width 8 --height 8 --spp-ladder 1 --reference '" + dir +
      "/var.exr'");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_EQ(r.err,
            "lucent: error: " + dir + "/var.exr: pixel (1, 0) channel var.R is not finite (inf)\n");
}

}  // namespace

// Where the verdict is weak it says so (the converge review's measurements): against a reference
// about as noisy as the rung, relMSE (which divides by the reference's noisy values) exceeds the
// noise estimate, and an unbiased setting was called biased (error/noise 1.5 at a rung of 64 spp
// against a reference of 16); and Sobol's stratified samples err less than variance / n says,
// so an unbiased verdict on them can hide a bias (max_depth=4: "unbiased" with Sobol, biased
// with independent samples).
TEST(Converge, VerdictSaysWhereItIsWeak) {
  lucent::Scene scene = lucent::parse_scene(kScene, "t.json");
  scene.film.width = 16;
  scene.film.height = 12;
  auto reference_of = [&](int spp) {
    lucent::Scene ref_scene = scene;
    ref_scene.integrator.seed = lucent::reference_seed(scene.integrator.seed);
    ref_scene.integrator.spp = spp;
    return lucent::test::render(ref_scene, lucent::test::render_options());
  };
  lucent::ConvergeOptions opt;
  opt.render = lucent::test::render_options();
  opt.spp_ladder = {4, 16};
  opt.settings = {lucent::parse_converge_setting("default"),
                  lucent::parse_converge_setting("sampler=independent")};
  const std::string noisy_reference = "; the reference's own noise is ";
  const std::string sobol = "; Sobol samples err less than their noise estimate";

  lucent::ConvergeResult few = lucent::run_convergence(scene, reference_of(8), opt);
  ASSERT_EQ(few.fits.size(), 2u);
  for (const lucent::ConvergeFit& f : few.fits)
    EXPECT_NE(f.verdict.find(noisy_reference), std::string::npos) << f.verdict;

  lucent::ConvergeResult many = lucent::run_convergence(scene, reference_of(1024), opt);
  ASSERT_EQ(many.fits.size(), 2u);
  for (const lucent::ConvergeFit& f : many.fits)
    EXPECT_EQ(f.verdict.find(noisy_reference), std::string::npos) << f.verdict;
  ASSERT_FALSE(many.fits[0].biased) << many.fits[0].verdict;
  EXPECT_NE(many.fits[0].verdict.find(sobol), std::string::npos) << many.fits[0].verdict;
  EXPECT_EQ(many.fits[1].verdict.find(sobol), std::string::npos) << many.fits[1].verdict;
}

}  // namespace test_converge
