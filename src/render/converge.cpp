// Convergence studies (lucent/converge.hpp): error against a reference for a ladder of sample
// counts or time budgets, fitted on log-log axes.
#include "lucent/converge.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>

#include "core/text.hpp"
#include "image/plot_svg.hpp"
#include "lucent/compare.hpp"
#include "lucent/error.hpp"
#include "lucent/limits.hpp"
#include "lucent/session.hpp"
#include "lucent/types.hpp"
#include "render/cancel_scope.hpp"
#include "render/converge_noise.hpp"
#include "render/integrator_knobs.hpp"

namespace lucent {

namespace {

int parse_int(const std::string& knob, const std::string& value, int min, int max) {
  // plain decimal, as the command line's integers (strtol took " 3", "+3" and "03")
  const long v =
      io::plain_decimal_integer(value) ? std::strtol(value.c_str(), nullptr, 10) : min - 1L;
  if (v < min || v > max)
    throw Error("setting " + knob + "=" + value + ": expected an integer from " +
                std::to_string(min) + " to " + std::to_string(max) +
                (io::plain_decimal_integer(value) ? "" : " in plain decimal"));
  return static_cast<int>(v);
}

int parse_positive_int(const std::string& knob, const std::string& value, int max) {
  return parse_int(knob, value, 1, max);
}

/// Least-squares slope of log(y) against log(x) over the points where both are > 0; NaN when
/// fewer than two such points have different x (it was 0, which read as a measured slope).
double log_log_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!(x[i] > 0) || !(y[i] > 0) || !std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
    double lx = std::log(x[i]), ly = std::log(y[i]);
    n += 1;
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  double den = n * sxx - sx * sx;
  if (n < 2 || !(std::abs(den) > 1e-12)) return std::numeric_limits<double>::quiet_NaN();
  return (n * sxy - sx * sy) / den;
}

/// A finite number >= lo (> lo when `strict`).
double parse_number(const std::string& knob, const std::string& value, double lo, bool strict) {
  io::CNumbers c_numbers;  // "0.5", whatever the process locale
  // plain decimal, as the command line's reals (strtod took "0x10" and " 1")
  const double v = io::plain_decimal_real(value) ? std::strtod(value.c_str(), nullptr)
                                                 : std::numeric_limits<double>::quiet_NaN();
  if (!std::isfinite(v) || (strict ? !(v > lo) : !(v >= lo)))
    throw Error("setting " + knob + ": expected a number " + (strict ? ">" : ">=") + " " +
                std::to_string(static_cast<int>(lo)) +
                (io::plain_decimal_real(value) ? "" : " in plain decimal"));
  // as the command line's real options (a larger clamp would be blamed on the scene file)
  if (std::abs(v) > FLT_MAX)
    throw Error("setting " + knob + ": must fit in a float (magnitude at most 3.4e38)");
  return v;
}

std::string fmt(const char* f, double v) {
  io::CNumbers c_numbers;  // "0.5", whatever the process locale
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

/// The reference's own expected share of a relMSE against it: mean of var_R / n_R / (R^2 + 0.01).
double reference_noise(const RenderResult& ref) {
  const std::size_t npix = static_cast<std::size_t>(ref.mean.width) * ref.mean.height;
  if (npix == 0 || ref.variance.rgb.size() != npix * 3 || ref.samples.size() != npix) return 0;
  double sum = 0;
  for (std::size_t i = 0; i < npix; ++i)
    for (int c = 0; c < 3; ++c) {
      if (ref.samples[i] < 2) continue;
      double r = ref.mean.rgb[i * 3 + c];
      sum += ref.variance.rgb[i * 3 + c] / double(ref.samples[i]) / (r * r + 0.01);
    }
  return sum / (3.0 * double(npix));
}

/// Whether two settings set the same knobs to the same values (their names aside).
bool same_knobs(const ConvergeSetting& a, const ConvergeSetting& b) {
  const auto knobs = [](const ConvergeSetting& s) {
    return std::tie(s.fast_math, s.precision, s.specialize, s.mis, s.max_depth, s.rr_depth,
                    s.filter, s.filter_radius, s.integrator, s.sampler, s.clamp, s.caustics,
                    s.splits, s.adaptive, s.min_spp, s.target_error);
  };
  return knobs(a) == knobs(b);
}

/// The fields of a setting made in code, each within what its knob takes (parse_converge_setting
/// makes only such): mis = 5 turned MIS on where caustics = 7 turned caustics off, and a
/// max_depth of -5, a NaN clamp or a NaN target meant "the scene's" without a word.
void check_setting_fields(const ConvergeSetting& s) {
  auto fail = [&](const std::string& what) {
    throw Error("converge: setting '" + s.name + "': " + what);
  };
  auto tri = [&](int v, const char* name) {
    if (v < -1 || v > 1) fail(std::string(name) + " must be -1 (the scene's), 0 or 1");
  };
  tri(s.mis, "mis");
  tri(s.caustics, "caustics");
  if (s.precision != -1 && s.precision != static_cast<int>(Precision::Float) &&
      s.precision != static_cast<int>(Precision::Double))
    fail("precision must be -1 (the options') or a Precision");
  if (s.max_depth < 0 || s.max_depth > limits::kMaxDepth)
    fail("max_depth must be 0 (the scene's) to " + std::to_string(limits::kMaxDepth));
  if (s.rr_depth < 0 || s.rr_depth > limits::kMaxDepth)
    fail("rr_depth must be 0 (the scene's) to " + std::to_string(limits::kMaxDepth));
  if (s.filter != -1 && !find_entry(static_cast<FilterType>(s.filter)))
    fail("filter must be -1 (the scene's) or a FilterType");
  if (!(s.filter_radius >= 0) || s.filter_radius > limits::kMaxFilterRadius)
    fail("filter_radius must be 0 (the scene's) or in (0, " + fmt("%g", limits::kMaxFilterRadius) +
         "]");
  if (s.integrator != -1 && !find_entry(static_cast<IntegratorType>(s.integrator)))
    fail("integrator must be -1 (the scene's) or an IntegratorType");
  if (s.sampler != -1 && !find_entry(static_cast<SamplerType>(s.sampler)))
    fail("sampler must be -1 (the scene's) or a SamplerType");
  if (std::isnan(s.clamp) || s.clamp > FLT_MAX)
    fail("clamp must be < 0 (the scene's) or a number from 0 to 3.4e38");
  if (s.splits < -1 || s.splits > limits::kMaxDielectricSplits)
    fail("splits must be -1 (the scene's) to " + std::to_string(limits::kMaxDielectricSplits));
  if (s.min_spp != 0 && (s.min_spp < 4 || s.min_spp > int(AdaptiveOptions{}.max_spp)))
    fail("min_spp must be 0 (the default) or 4 to " + std::to_string(AdaptiveOptions{}.max_spp));
  if (!(s.target_error >= 0) || s.target_error > FLT_MAX)
    fail("target_error must be 0 (off) or a positive number");
  // the parser's rules across knobs (a setting made in code combined or ignored them)
  if (s.adaptive && s.target_error > 0) fail("adaptive and target-error exclude each other");
  if (s.min_spp > 0 && !s.adaptive && !(s.target_error > 0))
    fail("min-spp needs adaptive or target-error");
}

}  // namespace

namespace converge_detail {

namespace {

/// The variance of a render's pixel-channel mean plus, with `ref_var`, the reference's: what noise
/// alone puts into (A - R)^2 there (a pixel of fewer than 2 samples adds none).
double noise_variance(const RenderResult& a, const RenderResult& ref, bool ref_var, std::size_t i,
                      int c) {
  double var = a.samples[i] >= 2 ? a.variance.rgb[i * 3 + c] / double(a.samples[i]) : 0;
  if (ref_var && ref.samples[i] >= 2) var += ref.variance.rgb[i * 3 + c] / double(ref.samples[i]);
  return var;
}

}  // namespace

double noise_relmse(const RenderResult& a, const RenderResult& ref) {
  const std::size_t npix = static_cast<std::size_t>(a.mean.width) * a.mean.height;
  if (npix == 0 || a.variance.rgb.size() != npix * 3 || a.samples.size() != npix) return 0;
  const bool ref_var = ref.variance.rgb.size() == npix * 3 && ref.samples.size() == npix;
  double sum = 0;
  std::size_t usable = 0;
  for (std::size_t i = 0; i < npix; ++i) {
    if (a.samples[i] >= 2) ++usable;
    for (int c = 0; c < 3; ++c) {
      const double r = ref.mean.rgb[i * 3 + c];
      sum += noise_variance(a, ref, ref_var, i, c) / (r * r + 0.01);
    }
  }
  if (usable * 2 < npix) return 0;  // most pixels without a variance estimate: none
  return sum / (3.0 * double(npix));
}

double excess_standard_error(const RenderResult& a, const RenderResult& ref) {
  const std::size_t npix = static_cast<std::size_t>(a.mean.width) * a.mean.height;
  if (npix < 2 || a.variance.rgb.size() != npix * 3 || a.samples.size() != npix ||
      ref.mean.rgb.size() != npix * 3)
    return 0;
  const bool ref_var = ref.variance.rgb.size() == npix * 3 && ref.samples.size() == npix;
  double sum = 0, sumsq = 0;
  for (std::size_t i = 0; i < npix; ++i) {
    double x = 0;  // the pixel's three channels: they share its paths
    for (int c = 0; c < 3; ++c) {
      const double r = ref.mean.rgb[i * 3 + c], d = a.mean.rgb[i * 3 + c] - r;
      x += (d * d - noise_variance(a, ref, ref_var, i, c)) / (r * r + 0.01);
    }
    sum += x;
    sumsq += x * x;
  }
  const double n = double(npix), mean = sum / n;
  const double spread = std::max(0.0, (sumsq - n * mean * mean) / (n - 1));
  return std::sqrt(spread / n) / 3.0;  // (relMSE averages over 3 n pixel-channels)
}

}  // namespace converge_detail

void ConvergeSetting::apply(Scene& scene, RenderOptions& options) const {
  if (fast_math) options.fast_math = true;
  if (precision >= 0) options.precision = static_cast<Precision>(precision);
  if (!specialize) options.specialize = false;
  if (mis >= 0) scene.integrator.mis = mis != 0;
  if (max_depth > 0) scene.integrator.max_depth = max_depth;
  if (rr_depth > 0) scene.integrator.rr_depth = rr_depth;
  if (integrator >= 0) scene.integrator.type = static_cast<IntegratorType>(integrator);
  if (filter >= 0) {
    FilterType t = static_cast<FilterType>(filter);
    if (t != scene.film.filter.type) scene.film.filter.radius = default_filter_radius(t);
    scene.film.filter.type = t;
  }
  if (filter_radius > 0) scene.film.filter.radius = filter_radius;
  if (sampler >= 0) scene.integrator.sampler = static_cast<SamplerType>(sampler);
  if (clamp >= 0) scene.integrator.clamp = clamp;
  if (caustics >= 0) scene.integrator.caustics = caustics == 1;
  if (splits >= 0) scene.integrator.dielectric_splits = splits;
}

ConvergeSetting parse_converge_setting(const std::string& text) {
  io::CNumbers c_numbers;  // "0.5", whatever the process locale
  ConvergeSetting s;
  s.name = text;
  if (text.empty()) throw Error("empty setting (expected e.g. default, fast-math, max_depth=2)");
  // (split at the '+', "max_depth=+3" said "setting max_depth=: ...")
  if (text.find("=+") != std::string::npos || text.find(":+") != std::string::npos)
    throw Error("setting '" + text + "': a value cannot start with + (+ joins knobs)");
  // every knob between two '+' (getline dropped a trailing empty one: "max_depth=3+" was read)
  std::vector<std::string> knobs{""};
  for (char c : text)
    if (c == '+')
      knobs.emplace_back();
    else
      knobs.back().push_back(c);
  std::map<std::string, std::string> given;  // what each knob sets -> the knob that set it
  for (const std::string& knob : knobs) {
    if (knob.empty())
      throw Error("setting '" + text + "': an empty knob (knobs are joined by one +)");
    std::string key = knob, value;
    std::size_t eq = knob.find('=');
    if (eq != std::string::npos) {
      key = knob.substr(0, eq);
      value = knob.substr(eq + 1);
    }
    for (char& c : key)
      if (c == '-') c = '_';
    // a knob that sets what another knob of the setting set (caustics+no-caustics, clamp=1+clamp=2,
    // float+double): refused, rather than the last one winning without a word
    std::string field = key;
    if (key == "no_caustics") field = "caustics";
    if (key == "no_mis") field = "mis";
    if (key == "double" || key == "float") field = "precision";
    {  // (default+default was taken, fast-math+fast-math refused)
      auto [it, fresh] = given.emplace(field, knob);
      if (!fresh)
        throw Error("setting '" + text + "': " + knob + " and " + it->second +
                    " set the same thing");
    }
    auto no_value = [&] {
      if (eq != std::string::npos) throw Error("setting " + knob + ": " + key + " takes no value");
    };
    if (key == "default") {
      no_value();
    } else if (key == "fast_math") {
      no_value();
      s.fast_math = true;
    } else if (key == "double" || key == "float") {
      no_value();
      s.precision = static_cast<int>(parse_precision(key, "setting " + knob));
    } else if (key == "precision") {
      s.precision = static_cast<int>(parse_precision(value, "setting " + knob));
    } else if (key == "no_specialize") {
      no_value();
      s.specialize = false;
    } else if (key == "no_mis") {
      no_value();
      s.mis = 0;
    } else if (key == "mis") {
      no_value();
      s.mis = 1;
    } else if (key == "max_depth") {
      s.max_depth = parse_positive_int(knob.substr(0, eq), value, limits::kMaxDepth);
    } else if (key == "rr_depth") {
      s.rr_depth = parse_positive_int(knob.substr(0, eq), value, limits::kMaxDepth);
    } else if (key == "filter") {
      std::string type = value, radius;
      std::size_t colon = value.find(':');
      if (colon != std::string::npos) {
        type = value.substr(0, colon);
        radius = value.substr(colon + 1);
        if (radius.empty())  // ("filter=box:" was taken as filter=box)
          throw Error("setting " + knob + ": an empty radius after ':' (filter=" + type +
                      " alone, or filter=" + type + ":RADIUS)");
      }
      std::optional<FilterType> t = find_type<FilterType>(type);
      if (!t)
        throw Error("setting " + knob + ": unknown filter '" + type + "' (expected " +
                    type_names<FilterType>() + ", optionally :RADIUS)");
      s.filter = static_cast<int>(*t);
      if (!radius.empty()) {
        const double r = io::plain_decimal_real(radius) ? std::strtod(radius.c_str(), nullptr) : 0;
        if (!(r > 0) || r > limits::kMaxFilterRadius)
          throw Error("setting " + knob + ": filter radius must be a number in (0, " +
                      fmt("%g", limits::kMaxFilterRadius) + "] pixels" +
                      (io::plain_decimal_real(radius) ? "" : " in plain decimal"));
        s.filter_radius = r;
      }
    } else if (key == "sampler") {
      std::optional<SamplerType> t = find_type<SamplerType>(value);
      if (!t)
        throw Error("setting " + knob + ": unknown sampler (expected " + type_names<SamplerType>() +
                    ")");
      s.sampler = static_cast<int>(*t);
    } else if (key == "clamp") {
      s.clamp = parse_number(knob, value, 0, false);
    } else if (key == "splits") {
      s.splits = parse_int(knob.substr(0, eq), value, 0, limits::kMaxDielectricSplits);
    } else if (key == "caustics" || key == "no_caustics") {
      no_value();
      s.caustics = key == "caustics" ? 1 : 0;
    } else if (key == "adaptive") {
      no_value();
      s.adaptive = true;
    } else if (key == "min_spp") {
      // (from 4: "min-spp=-4" said "an integer from 1", and under the spelling min_spp; to an
      // adaptive render's most samples per pixel, which a study cannot raise: above it the
      // study failed once it reached the setting, after the reference and the settings before
      // it, with render_adaptive's "... <= max_spp, got 20000 and 16384")
      s.min_spp = parse_int(knob.substr(0, eq), value, 4, int(AdaptiveOptions{}.max_spp));
    } else if (key == "target_error") {
      s.target_error = parse_number(knob, value, 0, true);
    } else if (key == "integrator") {
      std::optional<IntegratorType> t = find_type<IntegratorType>(value);
      if (!t)
        throw Error("setting " + knob + ": unknown integrator (expected " +
                    type_names<IntegratorType>() + ")");
      s.integrator = static_cast<int>(*t);
    } else {
      throw Error("setting '" + text + "': unknown knob '" + knob +
                  "' (expected default, fast-math, double, float, no-specialize, no-mis, mis, "
                  "max_depth=N, rr_depth=N, filter=" +
                  type_names<FilterType>("|") +
                  "[:R], integrator=NAME, sampler=" + type_names<SamplerType>("|") +
                  ", clamp=X, caustics, no-caustics, splits=N, adaptive, min-spp=N, "
                  "target-error=E, "
                  "joined by +)");
    }
  }
  if (s.adaptive && s.target_error > 0)
    throw Error("setting '" + text + "': adaptive and target-error exclude each other");
  if (s.min_spp > 0 && !s.adaptive && !(s.target_error > 0))
    throw Error("setting '" + text + "': min-spp needs adaptive or target-error");
  return s;
}

std::vector<ConvergeSetting> parse_converge_settings(const std::vector<std::string>& texts) {
  std::vector<ConvergeSetting> out;
  for (const std::string& text : texts) {
    ConvergeSetting parsed = parse_converge_setting(text);
    for (const ConvergeSetting& earlier : out)
      if (same_knobs(earlier, parsed))
        throw Error("'" + text + "' is " +
                    (earlier.name == text ? std::string("given twice")
                                          : "the same setting as '" + earlier.name + "'"));
    out.push_back(std::move(parsed));
  }
  return out;
}

namespace {

/// What the verdict rests on, where it is weak (the converge review measured both):
/// - the noise estimate (variance / n) assumes independent samples, and Sobol's stratified samples
///   err less than it: on default.json max_depth=4 was "unbiased (error/noise 0.75)" with Sobol
///   samples and biased with independent ones, its bias more than half its error;
/// - relMSE divides by the reference's own noisy values, so a reference about as noisy as the
///   rung inflates the error beyond what the noise explains: an unbiased setting was "biased"
///   (error/noise 1.5) against a reference of 16 spp at a rung of 64.
void add_verdict_notes(ConvergeFit& f, const ConvergePoint& last, SamplerType sampler) {
  if (last.noise_relmse > 0 &&
      last.reference_noise_relmse > ConvergeFit::kReferenceShare * last.noise_relmse)
    f.verdict += "; the reference's own noise is " +
                 fmt("%.0f", 100 * last.reference_noise_relmse / last.noise_relmse) +
                 "% of the noise at the last rung, which makes the verdict and the slopes "
                 "unreliable: use a reference of many more samples than the top rung";
  else if (!f.biased && last.noise_relmse > 0 && sampler == SamplerType::Sobol)
    f.verdict +=
        "; Sobol samples err less than their noise estimate (variance / n) says, so a bias can "
        "hide under it: sampler=independent tells";
}

}  // namespace

std::uint32_t reference_seed(std::uint32_t scene_seed) { return scene_seed ^ 0x5bd1e995u; }

std::vector<int> default_spp_ladder(int max_spp) {
  std::vector<int> out;
  // (in 64 bits: an int doubling past 2^30 overflowed, and the loop never ended)
  for (std::int64_t s = 1; s <= max_spp; s *= 2) out.push_back(static_cast<int>(s));
  if (max_spp >= 1 && (out.empty() || out.back() != max_spp)) out.push_back(max_spp);
  return out;
}

int default_reference_spp(const std::vector<int>& spp_ladder) {
  if (spp_ladder.empty()) return 1024;
  const std::int64_t top = *std::max_element(spp_ladder.begin(), spp_ladder.end());
  return static_cast<int>(std::clamp<std::int64_t>(16 * top, 256, limits::kMaxSpp));
}

ConvergeFit fit_convergence(const std::vector<ConvergePoint>& points) {
  ConvergeFit f;
  f.points = points.size();
  if (points.empty()) {
    f.verdict = "no points";
    return f;
  }
  f.setting = points.front().setting;
  std::vector<double> t, spp, e;
  for (const ConvergePoint& p : points) {
    t.push_back(p.seconds);
    spp.push_back(static_cast<double>(p.spp));
    e.push_back(p.relmse);
  }
  f.slope_spp = log_log_slope(spp, e);
  // one spp repeated (a ladder 2 2 2, a target-error setting's one render): the times differ by
  // noise alone, and a slope against them would be noise too
  f.slope_time = std::isnan(f.slope_spp) ? f.slope_spp : log_log_slope(t, e);
  std::size_t k = std::min<std::size_t>(3, points.size());
  f.tail_slope_spp = log_log_slope(std::vector<double>(spp.end() - k, spp.end()),
                                   std::vector<double>(e.end() - k, e.end()));
  const ConvergePoint& last = points.back();
  // how many standard errors the excess over the noise is (infinite without an estimate of it)
  double sigmas = INFINITY;
  if (last.noise_relmse > 0) {
    f.excess_ratio = last.relmse / last.noise_relmse;
    if (last.excess_standard_error > 0)
      sigmas = (last.relmse - last.noise_relmse) / last.excess_standard_error;
    f.biased = f.excess_ratio > ConvergeFit::kBiasRatio && sigmas > ConvergeFit::kBiasSigmas;
  } else {
    f.biased = points.size() >= 3 && f.tail_slope_spp > -0.5;
  }
  f.bias_relmse = std::max(0.0, last.relmse - last.noise_relmse);
  if (!f.biased) {
    // without a variance estimate (1-spp rungs, a constant image) only the tail's slope tells,
    // over three rungs or more: fewer said "unbiased" of a setting whose error was 0.47 (a
    // clamp at 0.01) on one rung of 1 spp
    f.verdict =
        // the excess held by a few pixels: their rare bright samples, or a bias confined to
        // them (a small caustic clamped), which this test cannot tell apart: the standard error
        // comes from the same pixels, and k biased pixels score about sqrt(k) standard errors
        // whatever their bias (it said "unbiased" of them; "biased", first, of the Cornell box)
        last.noise_relmse > 0 && f.excess_ratio > ConvergeFit::kBiasRatio
            ? "undetermined (error/noise " + fmt("%.2f", f.excess_ratio) +
                  " at the last rung, but a few pixels hold the excess, " + fmt("%.1f", sigmas) +
                  " standard errors: rare bright samples, or a bias confined to them; more "
                  "samples tell)"
        : last.noise_relmse > 0
            ? "unbiased (error/noise " + fmt("%.2f", f.excess_ratio) + " at the last rung)"
        : last.relmse == 0 ? std::string("unbiased (no error at the last rung)")
        : points.size() < 3 || std::isnan(f.tail_slope_spp)
            ? "undetermined (no variance estimate, and too few rungs for a slope)"
            : "unbiased (no variance estimate; tail slope " + fmt("%.2f", f.tail_slope_spp) + ")";
    return f;
  }
  std::string where;
  // the render's own noise: the reference's share of noise_relmse does not fall with time
  const double own_noise = std::max(0.0, last.noise_relmse - last.reference_noise_relmse);
  if (own_noise > 0 && f.bias_relmse > 0 && last.seconds > 0) {
    // noise ~ c / t: it falls to the floor at t = noise * t_last / bias (with the reference's
    // share extrapolated too, a reference of the top rung's spp doubled the time and the spp)
    double ratio = own_noise / f.bias_relmse;
    f.floor_seconds = last.seconds * ratio;
    if (f.floor_seconds < points.front().seconds)
      where = " (the bias dominates from the first rung on)";
    else
      where = " (the noise falls below it after ~" + fmt("%.3g", f.floor_seconds) + " s, ~" +
              fmt("%.3g", double(last.spp) * ratio) + " spp)";
  }
  f.verdict = "biased: error stops decreasing at ~relMSE " + fmt("%.2e", f.bias_relmse) + where;
  return f;
}

void check_convergence_options(const ConvergeOptions& options, const Scene* scene) {
  const bool by_time = !options.time_ladder.empty();
  if ((by_time ? options.time_ladder.size() : options.spp_ladder.size()) == 0)
    throw Error("converge: the ladder is empty");
  int largest = 0;
  for (int s : options.spp_ladder) {
    if (s < 1 || s > limits::kMaxSpp)
      throw Error("converge: spp ladder values must be in [1, " + std::to_string(limits::kMaxSpp) +
                  "], got " + std::to_string(s));
    largest = std::max(largest, s);
  }
  static_assert(limits::kMaxSeconds == 1e7, "the message below says (0, 1e7]");
  for (double t : options.time_ladder)
    if (!(t > 0 && t <= limits::kMaxSeconds)) {
      char got[32];
      std::snprintf(got, sizeof got, "%g", t);
      throw Error(std::string("converge: time ladder values must be in (0, 1e7] seconds, got ") +
                  got);
    }
  // a rung given twice: an spp rung rendered the same samples twice, and the fit of two equal
  // points said "slope n/a"; a time rung measured the same budget again
  if (by_time) {
    std::set<double> seen;
    for (double t : options.time_ladder)
      if (!seen.insert(t).second)
        throw Error("converge: the time ladder gives " + fmt("%g", t) +
                    " s twice (each budget is one rung)");
  } else {
    std::set<int> seen;
    for (int s : options.spp_ladder)
      if (!seen.insert(s).second)
        throw Error("converge: the spp ladder gives " + std::to_string(s) +
                    " twice (each sample count is one rung)");
  }
  for (size_t i = 0; i < options.settings.size(); ++i) {
    const ConvergeSetting& setting = options.settings[i];
    check_setting_fields(setting);
    // (parse_converge_settings refuses these; a ConvergeSetting made in code was taken twice)
    for (size_t j = 0; j < i; ++j)
      if (same_knobs(options.settings[j], setting))
        throw Error("converge: setting '" + setting.name + "' sets what setting '" +
                    options.settings[j].name + "' sets (each would render the same)");
    if ((setting.adaptive || setting.target_error > 0) && by_time)
      throw Error("converge: setting " + setting.name + " is adaptive: use an spp ladder");
    // a knob that the setting's integrator does not read would be a setting that changes
    // nothing, reported as if it did (clamp=1 on a whitted scene: "x0.53 of default", noise)
    if (scene) {
      using render_detail::IntegratorKnob;
      const IntegratorType type = setting.integrator >= 0
                                      ? static_cast<IntegratorType>(setting.integrator)
                                      : scene->integrator.type;
      const std::pair<bool, std::pair<IntegratorKnob, const char*>> knobs[] = {
          {setting.max_depth > 0, {IntegratorKnob::MaxDepth, "max_depth"}},
          {setting.rr_depth > 0, {IntegratorKnob::RrDepth, "rr_depth"}},
          {setting.clamp >= 0, {IntegratorKnob::Clamp, "clamp"}},
          // (no-caustics is not: turning off what is off, as render's --no-caustics)
          {setting.caustics == 1, {IntegratorKnob::Caustics, "caustics"}},
          {setting.splits >= 0, {IntegratorKnob::Splits, "splits"}},
          {setting.mis >= 0, {IntegratorKnob::Mis, "mis"}}};
      for (const auto& [given, knob] : knobs)
        if (given)
          if (const char* why = render_detail::knob_ignored(type, knob.first))
            throw Error("converge: setting '" + setting.name + "': " + knob.second + ": " + why +
                        ", and the setting renders with " + type_name(type));
    }
    // an adaptive setting skips the rungs below its pilot (run_convergence): with none at or
    // above it, it rendered nothing and vanished from the table, the CSV and the plot
    if (!setting.adaptive) continue;
    const int pilot =
        setting.min_spp > 0 ? setting.min_spp : static_cast<int>(AdaptiveOptions{}.min_spp);
    if (largest < pilot)
      throw Error("converge: setting '" + setting.name + "' has no rung at or above its pilot of " +
                  std::to_string(pilot) + " spp (the ladder's largest rung is " +
                  std::to_string(largest) + "): add a rung of at least " + std::to_string(pilot) +
                  " spp or lower its min-spp");
  }
}

ConvergeResult run_convergence(const Scene& scene, const RenderResult& reference,
                               const ConvergeOptions& given) {
  // the rungs in ascending order: the verdict reads the last point as the largest rung, the fit
  // the last three, the time to a common error the first and the last (a ladder 1024,4,8 was
  // judged at 8 spp: "unbiased" for a setting judged biased on 4,8,1024)
  check_convergence_options(given, &scene);  // first: a NaN rung is no order for std::sort
  ConvergeOptions options = given;
  std::sort(options.spp_ladder.begin(), options.spp_ladder.end());
  std::sort(options.time_ladder.begin(), options.time_ladder.end());
  check_comparable_image(reference, "the reference image");  // every error against it would be NaN
  if (reference.mean.width != scene.film.width || reference.mean.height != scene.film.height)
    throw Error("the reference image is " + std::to_string(reference.mean.width) + "x" +
                std::to_string(reference.mean.height) + ", the scene renders " +
                std::to_string(scene.film.width) + "x" + std::to_string(scene.film.height));
  // a lucent render at the ladder's own seed holds the rungs' own samples (the same numbers for
  // the same pixel, index and dimension), which hides their error: `lucent converge` refused such
  // a --reference, but the library (and Python's converge) took it, and reported relMSE 0.62x
  // the noise of an unbiased ladder against a reference integrator render at the scene's seed
  if (!reference.sampler.empty() && reference.seed == scene.integrator.seed)
    throw Error("the reference image was rendered with seed " + std::to_string(reference.seed) +
                ", the ladder's: its samples include the rungs' own, which would hide their "
                "error; render it with another seed (lucent::reference_seed)");
  std::vector<ConvergeSetting> settings = options.settings;
  if (settings.empty()) settings.push_back(ConvergeSetting{});
  const bool by_time = !options.time_ladder.empty();
  const std::size_t rungs = by_time ? options.time_ladder.size() : options.spp_ladder.size();

  // one session for the whole study: settings change only the scene's data or the build
  // options, so the BVH is built once and each kernel variant once; the rungs of a setting
  // accumulate progressively (a rung of N spp continues the previous rung's samples, which are
  // those a fresh render of N spp would draw)
  std::optional<Renderer> own;
  Renderer* renderer = options.renderer;
  if (!renderer) {
    SessionOptions so;
    so.device = options.render.device;
    so.kernel_dir = options.render.kernel_dir;
    so.cache_dir = options.render.cache_dir;
    so.pass_seconds = options.render.pass_seconds;
    so.on_warning = options.render.on_warning;
    renderer = &own.emplace(so);
  }
  // the study is one operation for the session's cancel(): one asked for between two rungs (from
  // on_point, or another thread while a rung is compared or a setting's kernel built) stops it
  // too; each render call cleared it as it began, and the ladder went on. Its cancel flag is the
  // study's while it runs, the session's own again afterwards (a caller's session kept a pointer
  // to a flag that may not outlive this call). Refused first, changing nothing, while the session
  // is busy: the study cleared the cancel() of another thread's render and swapped its flag, then
  // failed on set_build_options, and that render ran its full time.
  render_detail::CancelScope cancel_scope(*renderer, "run_convergence", options.render.cancel);

  ConvergeResult result;
  CompareOptions co;
  co.image_mean_test = false;
  bool cancelled = false;
  const double ref_noise = reference_noise(reference);
  for (const ConvergeSetting& setting : settings) {
    if (cancel_scope.cancelled()) break;
    Scene s = scene;
    RenderOptions o = options.render;
    setting.apply(s, o);
    try {
      renderer->set_build_options(o.precision, o.fast_math, o.specialize);
      renderer->set_scene(s);
    } catch (const Error&) {
      // a stop during the setting's kernel build, where the build failed on it (PoCL's LLVM,
      // when its handlers were in place) or it cancelled a wait for another process's build:
      // the study is cancelled and keeps its rungs (they were lost with the error)
      if (cancel_scope.cancelled()) break;
      throw;
    }
    renderer->reset();
    AdaptiveOptions ao;
    if (setting.min_spp > 0) ao.min_spp = static_cast<std::uint32_t>(setting.min_spp);
    std::vector<ConvergePoint> pts;
    // a target-error setting is one render, whatever the ladder
    const std::size_t setting_rungs = setting.target_error > 0 ? 1 : rungs;
    for (std::size_t i = 0; i < setting_rungs && !cancelled; ++i) {
      if (cancel_scope.cancelled()) {
        cancelled = true;
        break;
      }
      if (setting.target_error > 0) {
        ao.target_error = setting.target_error;
        renderer->render_adaptive(ao, options.render.on_progress);
      } else if (setting.adaptive) {
        // the rungs' budgets rise: each continues the previous rung's render
        if (options.spp_ladder[i] < static_cast<int>(ao.min_spp)) continue;
        // (the rungs ascend: a rung below the previous one would continue a render of more
        // samples, as a ladder 16,8 given unsorted did, reporting 16 spp twice; kept as a guard)
        if (ao.budget_spp > 0 && options.spp_ladder[i] < ao.budget_spp) renderer->reset();
        ao.budget_spp = options.spp_ladder[i];
        renderer->render_adaptive(ao, options.render.on_progress);
      } else if (by_time) {
        double t = options.time_ladder[i];
        if (t <= renderer->result().seconds) renderer->reset();
        renderer->render(0, t - renderer->result().seconds, options.render.on_progress);
      } else {
        std::uint64_t spp = static_cast<std::uint64_t>(options.spp_ladder[i]);
        if (spp < renderer->spp()) renderer->reset();
        if (spp > renderer->spp())
          renderer->render(spp - renderer->spp(), 0, options.render.on_progress);
      }
      RenderResult r = renderer->result();
      if (r.cancelled) {
        cancelled = true;
        break;
      }
      CompareResult c = compare_images(r, reference, co);
      ConvergePoint p;
      p.setting = setting.name;
      p.spp = r.spp;
      p.seconds = r.seconds;
      double samples = double(r.spp) * s.film.width * s.film.height;
      p.samples_per_second = r.seconds > 0 ? samples / r.seconds : 0;
      p.rays_per_second = r.seconds > 0 ? double(r.rays) / r.seconds : 0;
      p.rmse = c.rmse;
      p.relmse = c.relmse;
      p.noise_relmse = converge_detail::noise_relmse(r, reference);
      if (p.noise_relmse > 0)
        p.excess_standard_error = converge_detail::excess_standard_error(r, reference);
      p.reference_noise_relmse = ref_noise;
      p.estimated_relmse = r.estimated_relmse;
      p.halves_relmse = r.halves_relmse;
      if (options.on_point)
        cancel_scope.hold("run_convergence's on_point", [&] { options.on_point(p); });
      pts.push_back(p);
    }
    if (!pts.empty()) {
      result.fits.push_back(fit_convergence(pts));
      add_verdict_notes(result.fits.back(), pts.back(), s.integrator.sampler);
      result.points.insert(result.points.end(), pts.begin(), pts.end());
    }
    if (cancelled) break;
  }
  return result;
}

std::string convergence_csv(const ConvergeResult& result) {
  io::CNumbers c_numbers;  // "0.5", whatever the process locale
  std::string out =
      "setting,spp,seconds,samples_per_s,rmse,relmse,noise_relmse,rays_per_s,"
      "reference_noise_relmse,estimated_relmse,halves_relmse\n";
  char buf[256];
  for (const ConvergePoint& p : result.points) {
    std::string name = p.setting;
    if (name.find_first_of(",\"\n") != std::string::npos) {
      std::string q = "\"";
      for (char c : name) q += c == '"' ? std::string("\"\"") : std::string(1, c);
      name = q + "\"";
    }
    std::snprintf(buf, sizeof buf, ",%llu,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n",
                  static_cast<unsigned long long>(p.spp), p.seconds, p.samples_per_second, p.rmse,
                  p.relmse, p.noise_relmse, p.rays_per_second, p.reference_noise_relmse,
                  p.estimated_relmse, p.halves_relmse);
    out += name + buf;
  }
  return out;
}

double time_to_relmse(const std::vector<ConvergePoint>& points, double error) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    const ConvergePoint& b = points[i];
    if (!(b.relmse <= error)) continue;
    if (i == 0) return b.seconds;
    const ConvergePoint& a = points[i - 1];
    if (!(a.relmse > 0 && b.relmse > 0 && a.seconds > 0 && b.seconds > 0) || a.relmse == b.relmse)
      return b.seconds;
    const double f = std::log(error / a.relmse) / std::log(b.relmse / a.relmse);
    return std::exp(std::log(a.seconds) + f * std::log(b.seconds / a.seconds));
  }
  return std::numeric_limits<double>::infinity();
}

namespace {

plot::LogLogPlot convergence_plot(const ConvergeResult& result, const std::string& title) {
  plot::LogLogPlot plot;
  plot.title = title;
  plot.x_label = "render time (s, kernel build excluded)";
  plot.y_label = "relMSE against the reference";
  for (const ConvergeFit& f : result.fits) {
    plot::Series s;
    s.name = f.setting + " (slope " +
             (std::isnan(f.slope_time) ? std::string("n/a") : fmt("%.2f", f.slope_time)) +
             (f.biased ? ", biased)" : ")");
    for (const ConvergePoint& p : result.points)
      if (p.setting == f.setting) {
        s.x.push_back(p.seconds);
        s.y.push_back(p.relmse);
      }
    plot.series.push_back(std::move(s));
  }
  return plot;
}

}  // namespace

std::string convergence_svg(const ConvergeResult& result, const std::string& title) {
  io::CNumbers c_numbers;  // "0.5", whatever the process locale
  return plot::log_log_svg(convergence_plot(result, title));
}

Image convergence_image(const ConvergeResult& result, const std::string& title) {
  io::CNumbers c_numbers;  // "0.5", whatever the process locale
  return plot::log_log_image(convergence_plot(result, title));
}

}  // namespace lucent
