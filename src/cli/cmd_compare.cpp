// `lucent compare A B`: the statistical comparison of two renders (docs/compare.md). Prints the
// metrics and PASS or FAIL; exits 0 on PASS, 1 on FAIL or error.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>

#include "cli/commands.hpp"
#include "cli/stop_signals.hpp"
#include "core/file_io.hpp"
#include "image/image_probe.hpp"
#include "lucent/compare.hpp"
#include "lucent/error.hpp"
#include "lucent/image.hpp"

namespace lucent::cli {

namespace {

struct CompareArgs {
  std::string a, b;
  CompareOptions options;
  bool no_mean_test = false;
  std::string zmap;
};

CompareArgs& compare_args() {
  static CompareArgs a;
  return a;
}

}  // namespace

CLI::App* add_compare_command(CLI::App& app) {
  CompareArgs& a = compare_args();
  CLI::App* cmd = app.add_subcommand(
      "compare", "Compare two renders statistically (z-test per pixel; EXR with var.*/n layers)");
  cmd->add_option("a", a.a, "First image (.exr with variance layers, or any image)")
      ->required()
      ->check(non_empty());
  cmd->add_option("b", a.b, "Second image, the reference for relMSE")
      ->required()
      ->check(non_empty());
  cmd->add_option("--alpha", a.options.alpha, "Family-wise significance level (default 0.01)")
      ->check(lucent::cli::real_range(1e-12, 0.5));
  cmd->add_option("--min-pass", a.options.min_pass_fraction,
                  "Fraction of pixels that must pass (default 0.995)")
      ->check(lucent::cli::real_range(0.0, 1.0));
  cmd->add_option("--abs-epsilon", a.options.abs_epsilon,
                  "Absolute error allowed where variances are zero (default 1e-5)")
      ->check(lucent::cli::non_negative_real());
  cmd->add_option("--rel-epsilon", a.options.rel_epsilon,
                  "Relative error allowed where variances are zero (default 1e-4)")
      ->check(lucent::cli::non_negative_real());
  cmd->add_flag("--no-mean-test", a.no_mean_test, "Skip the test of the image means");
  cmd->add_option("--zmap", a.zmap,
                  "Write the per-pixel z values (signed, per channel) to this .exr or .pfm file")
      ->check(non_empty());
  return cmd;
}

int run_compare_command() {
  CompareArgs& a = compare_args();
  a.options.image_mean_test = !a.no_mean_test;
  if (!a.zmap.empty()) {
    for (const std::string& in : {a.a, a.b})
      if (io::same_file(a.zmap, in))
        throw Error(a.zmap + ": is an input of the comparison; refusing to overwrite it");
    // before reading anything: the format, a directory, a place that cannot be written
    const std::string ext = io::lower_extension(a.zmap);
    if (ext != ".exr" && ext != ".pfm")
      throw Error(a.zmap + ": unknown z map format '" + ext +
                  "' (use .exr or .pfm: z values are signed)");
    io::check_output_path(a.zmap, {a.a, a.b});
  }
  image_detail::Format fa, fb;
  const RenderResult ra = image_detail::read_render(a.a, &fa),
                     rb = image_detail::read_render(a.b, &fb);
  // a NaN or an infinity in an input is an error in the file, not a difference between renders
  // (it failed its pixel, with "max |z| inf", as if the renders disagreed)
  check_comparable_image(ra, a.a);
  check_comparable_image(rb, a.b);
  // a display image (PNG, JPEG, BMP, TGA: tone-mapped, encoded, clipped) against a linear one
  // compares the display transform, not the renders
  const bool display_a = image_detail::is_display_format(fa);
  if (display_a != image_detail::is_display_format(fb))
    throw Error((display_a ? a.a : a.b) + ": a " + image_detail::format_name(display_a ? fa : fb) +
                " image holds display values (tone-mapped, clipped), and " +
                (display_a ? a.b : a.a) +
                " linear radiance: compare two linear images (.exr, .pfm, .hdr; lucent render "
                "-o x.exr), or two display images");
  if (ra.mean.width != rb.mean.width || ra.mean.height != rb.mean.height)
    throw Error(a.b + ": size " + std::to_string(rb.mean.width) + "x" +
                std::to_string(rb.mean.height) + " differs from " + a.a + " (" +
                std::to_string(ra.mean.width) + "x" + std::to_string(ra.mean.height) + ")");
  CompareResult r = compare_images(ra, rb, a.options);
  // a stop signal in the z map's write lets it end (it killed compare there, leaving a hidden
  // temporary file); the comparison is then not reported
  if (!a.zmap.empty()) {
    if (const int sig = run_with_stops_deferred([&] { write_image(a.zmap, r.z); })) {
      std::fprintf(stderr, "lucent: interrupted by %s: wrote %s in full first\n", signal_name(sig),
                   one_line(a.zmap).c_str());
      return 128 + sig;
    }
  }
  std::printf("A             %s%s\nB             %s%s\n", one_line(a.a).c_str(),
              ra.variance.rgb.empty() ? " (no variance layers)" : "", one_line(a.b).c_str(),
              rb.variance.rgb.empty() ? " (no variance layers)" : "");
  std::fputs(r.summary().c_str(), stdout);
  return r.passed ? 0 : 1;
}

}  // namespace lucent::cli
