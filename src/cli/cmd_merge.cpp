// `lucent merge PART... -o OUT`: adds the part files of sample-range renders (`lucent render
// --samples A:B`) into one image, exactly (lucent/parts.hpp, docs/parts.md). Checks that the parts
// come from the same scene, seed and film and that their ranges do not overlap, says which ranges
// are missing and the effective samples per pixel, and writes OUT atomically.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/stop_signals.hpp"
#include "lucent/error.hpp"
#include "lucent/parts.hpp"
#include "render/sample_stats.hpp"

namespace lucent::cli {

namespace {

struct MergeArgs {
  std::vector<std::string> parts;
  std::string output;
  std::string expect;
  bool complete = false;
  bool quiet = false;
};

MergeArgs& merge_args() {
  static MergeArgs a;
  return a;
}

}  // namespace

CLI::App* add_merge_command(CLI::App& app) {
  MergeArgs& a = merge_args();
  CLI::App* cmd = app.add_subcommand(
      "merge", "Merge the part files of sample-range renders (render --samples A:B) exactly");
  cmd->add_option("parts", a.parts, "Part files (.exr written by render --samples)")
      ->required()
      ->check(non_empty());
  cmd->add_option("-o,--output", a.output,
                  "Merged image: .exr (a part file, mergeable again), .png or .pfm")
      ->required()
      ->check(non_empty());
  cmd->add_flag("--complete", a.complete,
                "Fail (and write nothing) when sample ranges are missing");
  cmd->add_option("--expect", a.expect,
                  "A:B, the sample indices the parts should hold together: ranges missing from "
                  "it are reported (default: [0, the highest end a part asked for), which cannot "
                  "see a last part that was never written)")
      ->check(non_empty());
  cmd->add_flag("-q,--quiet", a.quiet, "Print only warnings and errors");
  return cmd;
}

int run_merge_command() {
  MergeArgs& a = merge_args();
  check_merge_output(a.output, a.parts);
  std::optional<SampleRange> expect;
  // what the parts hold together: many parts of at most 2^24 samples each (the per-part limit)
  if (!a.expect.empty()) expect = parse_sample_range(a.expect, "--expect", false);
  MergeReport r = merge_render_parts(a.parts);
  const PartInfo& info = r.merged.info;
  // a stop signal from here on lets the output be written in full (it killed the merge in the
  // write, leaving a hidden temporary file); before, it kills it with nothing written
  const int sig = run_with_stops_deferred([&] {
    check_merge_coverage(r, expect, a.complete, "--expect", "--complete");
    if (!r.missing.empty())
      std::fprintf(stderr, "lucent: warning: samples %s are missing: the image has fewer samples\n",
                   ranges_text(r.missing).c_str());
    write_merged(a.output, r.merged);
  });
  if (sig != 0) {
    std::fprintf(stderr, "lucent: interrupted by %s: wrote %s in full first\n", signal_name(sig),
                 one_line(a.output).c_str());
    return 128 + sig;
  }
  if (!a.quiet) {
    std::fprintf(stderr, "%s: %dx%d, %zu part(s), samples %s\n", one_line(a.output).c_str(),
                 info.width, info.height, r.order.size(), ranges_text(info.samples).c_str());
    std::fprintf(stderr, "effective samples per pixel (finite): min %u, mean %.2f, max %u\n",
                 r.min_spp, r.mean_spp, r.max_spp);
    if (info.nonfinite > 0)
      std::fprintf(
          stderr, "lucent: warning: %s\n",
          lucent::render_detail::nonfinite_warning(info.nonfinite, r.merged.acc.count).c_str());
  }
  return 0;
}

}  // namespace lucent::cli
