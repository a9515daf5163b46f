#pragma once
// Helpers shared by the tests: running the CLI, temporary files, rendering small scenes.
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "lucent/lucent.hpp"

namespace lucent::test {

struct CommandResult {
  int status = -1;  ///< exit status (128 + signal when killed)
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};

// AddressSanitizer reserves terabytes of address space for its shadow memory: a CLI built with it
// cannot start under `ulimit -v`, so the sanitizer build runs such cases without it.
// GCC defines __SANITIZE_ADDRESS__; clang says so through __has_feature.
#if defined(__SANITIZE_ADDRESS__)
#define LUCENT_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define LUCENT_TEST_ASAN 1
#endif
#endif
#ifdef LUCENT_TEST_ASAN
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif

/// Runs the lucent CLI with `args` (a shell-quoted string) and optional extra environment
/// assignments placed before the command (e.g. "LUCENT_DEVICE=foo").
CommandResult run_cli(const std::string& args, const std::string& env = "");

/// The environment assignment under which `lucent render` prints its progress line from its
/// first pass, and `lucent-mpi` (rank 0) once every rank has rendered a pass, not after a second of
/// rendering: the stop-signal tests wait for that line before their signal (docs/testing.md).
inline constexpr char kEarlyProgress[] = "LUCENT_TEST_EARLY_PROGRESS=1";
/// A fresh directory under the build tree, removed at the end of the test program.
std::string temp_dir();
/// Writes the kernel sources this build embeds into a fresh directory and returns it (for
/// LUCENT_KERNEL_DIR: a kernel with an injected error, another source).
std::string kernel_copy();

/// Writes `text` to `path`.
void write_file(const std::string& path, const std::string& text);

/// The content of `path` ("" when it cannot be read).
std::string read_file(const std::string& path);

/// CRC-32 (ISO 3309), as PNG chunks carry it, computed here.
std::uint32_t crc32(const std::string& data);

/// A PNG file written by hand (stb_image_write writes neither 16 bits nor palettes): the IHDR of
/// `width` x `height`, `bit_depth` and `colour_type`, then `chunks` (tag and data: a PLTE), then
/// `rows` (each row's filter byte included) as one zlib stream of stored deflate blocks; CRC-32
/// and Adler-32 computed here. `rows` must be under 64 KiB.
std::string png_file(int width, int height, int bit_depth, int colour_type,
                     const std::vector<std::pair<std::string, std::string>>& chunks,
                     const std::string& rows);

/// The message of the lucent::Error that `f` throws, "" when it throws none, and "unexpected
/// exception type: ..." for any other exception.
std::string error_of(const std::function<void()>& f);

/// Sets an environment variable (or unsets it, for nullptr) while alive; restores it after.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value);
  ~ScopedEnv();
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::string name_, old_;
  bool had_ = false;
};

/// Path of a file under the source tree.
std::string source_path(const std::string& rel);

/// ../shared/assets/<rel> beside the project, or "" when ../shared is absent.
std::string shared_asset(const std::string& rel);

/// The session defaults of the test programs, as the `lucent` command takes them: device, kernel
/// directory and cache directory from LUCENT_DEVICE, LUCENT_KERNEL_DIR and LUCENT_CACHE_DIR (so
/// that `LUCENT_DEVICE=... ctest` and planted-bug runs through LUCENT_KERNEL_DIR reach the tests).
SessionOptions session_options();
/// Their device selector and kernel directory alone.
std::string device();
std::string kernel_dir();
/// The resolved kernel binary cache directory ("" when LUCENT_CACHE_DIR=off).
std::string cache_dir();

/// RenderOptions with the test defaults (device, kernel and cache directories).
RenderOptions render_options();

/// lucent::render with the test defaults filled in where `options` leaves them empty.
RenderResult render(const Scene& scene, RenderOptions options = {});

/// The sampler of the statistical tests: `scene` with integrator.sampler = independent, so that
/// a pixel's sample variance / n is the variance of its mean, as the z-tests assume (Sobol
/// samples are stratified: that estimate is then no longer the variance of the mean).
Scene with_independent_samples(Scene scene);

/// Parses a JSON scene held in memory (relative file names resolve against a temporary directory),
/// with the independent sampler unless the JSON names one ("sampler" in "integrator"): tests of
/// the Sobol sampler name it.
Scene scene_from(const std::string& json);

/// Renders a JSON scene held in memory with `spp` samples per pixel. `specialize` false compiles
/// every kernel feature (RenderOptions::specialize): the one program that the stability,
/// precision and known-answer tests share, built once per cache instead of once per scene.
RenderResult render_json(const std::string& json, int spp, bool specialize = true);

/// The report of `lucent info`: "key   value" lines keyed by section and key ("lights/point" ->
/// "1", "film" -> "40x30").
std::map<std::string, std::string> parse_report(const std::string& out);

/// Number of lines in `s` that are not empty.
int count_lines(const std::string& s);

/// dir/flat.json: a lamp filling the left of a 500x400 view, its edge slanted, nothing else (4
/// spp, seed 3): every sample of a pixel off the edge is the same, so that its part file
/// compresses to about 75 KB where its PFM takes 2.4 MB (a pixel on the edge differs with its
/// samples). Returns its path. (16 spp until 1 Dec 2026: the same file sizes, four times the
/// render, 0.7 s of CPU a render here.)
std::string flat_lamp_scene(const std::string& dir);

/// The samples per second of `lucent render SCENE --time 0.5 -o OUT` (its summary line), to size
/// a test's render for this machine; -1 when the render fails or prints no rate.
double cli_samples_per_second(const std::string& scene, const std::string& out);

/// The peak resident memory that `work` adds, in bytes, measured in a child process (forked; its
/// peak reset first through /proc/self/clear_refs, then VmHWM less the VmRSS before `work`); -1
/// when it cannot be measured or `work` returns false (or throws).
double child_peak_bytes(const std::function<bool()>& work);

/// The text of an OBJ file of `n` separate small triangles scattered in a 10-unit cube (a "soup":
/// the BVH's leaves hold one triangle each), the same for the same `n`.
std::string soup_obj_text(int n);

/// z threshold of a two-sided test at family-wise significance alpha over m tests (Sidak).
double sidak_z(double alpha, int m);

/// P(chi-square with `dof` degrees of freedom > chi2): the regularized upper incomplete gamma
/// function Q(dof/2, chi2/2), by series or continued fraction.
double chi2_pvalue(double chi2, int dof);

/// Pearson's chi-square statistic of observed against expected counts, with every cell whose
/// expected count is below `min_expected` pooled into one (counted as a cell only when the pool
/// reaches min_expected itself).
struct PooledChi2 {
  double chi2 = 0;
  int cells = 0;               ///< cells in the statistic (dof = cells - 1)
  double pooled_observed = 0;  ///< observed count in the small cells
  double pooled_expected = 0;  ///< expected count in the small cells
};
PooledChi2 pooled_chi2(const std::vector<double>& observed, const std::vector<double>& expected,
                       double min_expected = 5);

/// Collects scene loading warnings (scene_detail::warn) while alive, instead of printing them.
class CaptureWarnings {
 public:
  CaptureWarnings();
  ~CaptureWarnings();
  CaptureWarnings(const CaptureWarnings&) = delete;
  CaptureWarnings& operator=(const CaptureWarnings&) = delete;
  const std::vector<std::string>& all() const;
  /// How many warnings contain `needle`.
  int count(const std::string& needle) const;
  /// All warnings, one per indented line (for failure messages).
  std::string dump() const;
};

/// One-sample z-test of a render against closed-form pixel values: every pixel channel must have
/// |mean - expected| / se below sidak_z(1e-3, pixels * 3), with se = sqrt(var / n) plus a floor of
/// 1e-6 + 1e-4 |expected| (float rounding of near-zero-variance estimators is not a sampling
/// error). Also: no non-finite sample. Reports the first failing pixels with ADD_FAILURE.
void expect_matches(const RenderResult& r, const std::function<double(int, int, int)>& expected);

// E N N S+ L: the light that a caustic sends on to another diffuse surface. A light at
// (0, 0, 2.5) under a mirror ceiling z = 3.2 (x, y within +-3, facing down); a black square
// z = 1.95 (x, y within +-1.5) shades the diffuse floor z = 0 (x, y within +-6) from it, so the
// floor is lit only by the mirror, in a ring outside the square's shadow. Just under the black
// square, a diffuse "wall" z = 1.9 of the same size faces the floor: the light and its mirror
// image are above it, so its only light is the floor's, i.e. light that came off the mirror.
// The camera at (0, 0, 0.5) looks straight up and sees nothing but the wall.
// `light` closes the shapes (a sphere lamp, then "]", or "]" and a point light); `more` adds
// shapes (before `light`), `camera` replaces the camera.
std::string bounced_caustic_scene(
    bool caustics, int max_depth, const std::string& light, const std::string& more = "",
    const std::string& camera =
        R"({"position": [0, 0, 0.5], "look_at": [0, 0, 1.9], "up": [0, 1, 0], "fov": 60})");

/// For bounced_caustic_scene: a vertical mirror x = 5.5 (y within +-3, z up to 3; `more`), and a
/// camera at (2, 0, 1) looking down at the floor at x within about 1.5 .. 2.5, where the black
/// square shades it from the lamp and from its image in the ceiling mirror. That floor's light
/// comes mostly off the lit ring of the floor, seen in the mirrors: floor, mirror wall, ceiling
/// mirror, lit floor, ceiling mirror, light (E N S S N S L), or through the wall alone.
inline constexpr const char* kMirrorWall = R"(, {"type": "triangles", "material": "mirror",
    "positions": [[5.5,-3,0],[5.5,3,0],[5.5,3,3],[5.5,-3,3]], "indices": [0,2,1, 0,3,2]})";
inline constexpr const char* kFloorBesideTheMirrorWall =
    R"({"position": [2, 0, 1], "look_at": [2, 0, 0], "up": [0, 1, 0], "fov": 50})";

/// A point light inside a glass sphere (radius 0.4, ior 1.5) in an open diffuse box (albedo 0.8:
/// floor, back and side walls 2 units wide and high), seen from the open front through a
/// `width` x `height` film with `filter` (a JSON object). With caustics every light reaching the
/// walls has passed the glass, so the whole image is light-traced, and a light path connects to
/// the camera at each wall it bounces off (up to max_depth - 2 connections), often several times
/// within one wide filter's reach.
std::string glass_lamp_box_scene(int width, int height, const std::string& filter, int max_depth);

/// The variance check of an ensemble of renders: `render(k)` for k = 0 .. R - 1 must be independent
/// renders of one scene. Returns the empirical variance of the pixel means across the renders
/// (ddof 1) over the mean reported variance of the mean (variance / samples), each summed over
/// the pixels, in channel `channel`: about 1 when the reported variance is right.
double ensemble_variance_ratio(const std::function<RenderResult(int)>& render, int R,
                               int channel = 1);

/// The image-mean test on pairs of independent renders: compares render(2 k) with render(2 k + 1)
/// for k = 0 .. pairs - 1 (compare_images) and returns the mean of the image-mean z^2 in channel
/// `channel`: about 1 when the image mean's standard error is right (z standard normal).
double mean_image_mean_z2(const std::function<RenderResult(int)>& render, int pairs,
                          int channel = 0);

}  // namespace lucent::test
