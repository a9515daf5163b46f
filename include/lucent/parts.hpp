#pragma once
// Sample-range renders ("parts") and their exact merge: `lucent render --samples A:B`, `lucent
// merge`, Slurm array jobs and the MPI renderer. A part holds the raw accumulation of some sample
// indices of one scene (double sums, sums of squares, counts) with what identifies the image
// (scene hash, seed, film, integrator). Parts of disjoint ranges of the same image add up to the
// accumulation of their union; merging adds them in ascending sample order, so a merge does not
// depend on the order its inputs are given in. File format: docs/parts.md.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lucent/accumulation.hpp"
#include "lucent/image.hpp"
#include "lucent/render.hpp"

namespace lucent {

class Renderer;

/// Sample indices [begin, end).
struct SampleRange {
  std::uint64_t begin = 0;
  std::uint64_t end = 0;
  bool operator==(const SampleRange& o) const { return begin == o.begin && end == o.end; }
};

/// "[0, 16)"; a list: "[0, 16), [32, 48)" ("none" when empty); a list of more than 8 ranges
/// names the first 6 and the last, and counts them:
/// "[0, 1), [2, 3), [4, 5), [6, 7), [8, 9), [10, 11), ..., [98, 99) (50 ranges)".
std::string range_text(const SampleRange& r);
std::string ranges_text(const std::vector<SampleRange>& rs);

/// The parts of `want` that `have` (sorted, disjoint ranges) does not cover.
std::vector<SampleRange> missing_ranges(const std::vector<SampleRange>& have,
                                        const SampleRange& want);

/// Parses "A:B" (0 <= A < B <= 2^32); throws lucent::Error naming `what` (e.g. "--samples")
/// otherwise. `per_part`: a range one render makes, so B - A <= limits::kMaxSpp too; a range that
/// many parts hold together (merge --expect) may be as long as 2^32.
SampleRange parse_sample_range(const std::string& text, const std::string& what = "--samples",
                               bool per_part = true);

/// What identifies a part's image and where its samples come from (a part file's header).
struct PartInfo {
  int width = 0, height = 0;
  std::uint64_t scene_hash = 0;  ///< Renderer::image_hash()
  std::uint32_t seed = 0;
  std::string sampler;                 ///< its name ("sobol", ...); empty from older part files
  std::string integrator;              ///< its name ("path", ...)
  std::string version;                 ///< lucent's version that rendered it
  std::string scene;                   ///< the scene file (informative)
  std::vector<SampleRange> samples;    ///< rendered: sorted, disjoint
  std::vector<SampleRange> requested;  ///< asked for: sorted, disjoint, covers `samples`
  DisplaySettings display;             ///< the film's display settings (for 8-bit outputs)
  std::uint64_t nonfinite = 0, rays = 0;
  double seconds = 0;  ///< kernel time, summed over the parts merged
};

/// A part: its header and its accumulation (acc.first_sample and acc.spp are unused: the
/// ranges are in info.samples).
struct RenderPart {
  PartInfo info;
  Accumulation acc;
};

/// Throws lucent::Error (naming `scene_path`) when the scene renders something part files cannot
/// hold: light-traced caustics (integrator.caustics with the path integrator), whose splats are
/// not per-pixel samples. Called by make_part, and by front ends before they render.
void check_part_scene(const Scene& scene, const std::string& scene_path);

/// The header of the part `renderer` makes of `requested`, without its samples (no sample
/// range, no counts, no sums copied): to check parts against each other before rendering them.
PartInfo part_header(const Renderer& renderer, const SampleRange& requested,
                     const std::string& scene_path);

/// The part a session holds after reset(range.begin) and render(range.end - range.begin),
/// possibly cut short: samples [first_sample, first_sample + spp) of `requested`. `scene_path`
/// is recorded for information.
RenderPart make_part(const Renderer& renderer, const SampleRange& requested,
                     const std::string& scene_path);

/// The part's mean, variance and counts as a RenderResult (as Renderer::result() computes them).
RenderResult part_result(const RenderPart& part);

/// How write_render_part compresses the file's channels (both lossless). Measured on a part of
/// scenes/default.json at 1920x1080 (tinyexr 1.0.1, zlib): ZIP wrote 81 MB in 2.7 s and is read
/// in 1.1 s; PIZ 77 MB in 1.2 s, read in 2.0 s; a flat image's ZIP file is smaller (500x400: 81
/// against 199 KB). Uncompressed would be 158 MB, in 0.6 s.
enum class PartCompression {
  zip,  ///< the default: the quickest read, for files that are kept and merged
  piz,  ///< a checkpoint's: a render waits for its writes, and reads it once
};

/// Writes a part file (an OpenEXR: the render's R, G, B, var.*, n layers, which `lucent compare`
/// reads, plus the raw double sums and the header as attributes, with a checksum of the sums;
/// docs/parts.md), atomically. Throws lucent::Error, writing nothing, for a part that reading
/// would refuse: no samples, ranges not sorted and disjoint, counts or sums that disagree with
/// the header, a non-finite sum, a `compression` outside the enum.
void write_render_part(const std::string& path, const RenderPart& part,
                       PartCompression compression = PartCompression::zip);
/// The host memory write_render_part allocates for a width x height part, beside the part
/// itself (its planes, the sums' 32-bit words and the EXR encoder), at most: for a front end's
/// check before it renders. Throws lucent::Error for a size not positive or a `compression`
/// outside the enum.
std::uint64_t part_write_bytes(int width, int height,
                               PartCompression compression = PartCompression::zip);
/// Reads a part file; throws lucent::Error naming the file and what is wrong.
RenderPart read_render_part(const std::string& path);
/// Reads only a part file's header.
PartInfo read_part_info(const std::string& path);

/// The result of a merge.
struct MergeReport {
  RenderPart merged;                       ///< the sum; info.samples: the union of the ranges
  std::vector<SampleRange> missing;        ///< gaps in [0, the highest end requested)
  std::uint32_t min_spp = 0, max_spp = 0;  ///< finite samples per pixel, over the pixels
  double mean_spp = 0;
  std::vector<std::string> order;  ///< the inputs in the order they were added
};

/// Adds parts one at a time, each checked against the first (film, seed, integrator, scene hash)
/// and against the ranges already added (no overlap). Double addition is not associative: the sum
/// depends on the order of the parts, so merge_render_parts adds them in ascending order of their
/// first sample (as lucent-mpi adds its ranks), whatever order they are given in.
class PartMerger {
 public:
  /// Throws lucent::Error (one line naming `name` and, for an overlap or a mismatch, the part it
  /// conflicts with).
  void check(const std::string& name, const PartInfo& info);
  /// check(), then records the header alone (to check a set of parts before reading their
  /// pixels); finish() is for a merger fed with add().
  void add_header(const std::string& name, const PartInfo& info);
  /// check(), then adds the part.
  void add(const std::string& name, const RenderPart& part);
  /// add(), taking the part: a first part becomes the sum without being copied (a film's sums
  /// held once, not twice: `lucent render --checkpoint` merges beside its session).
  void add(const std::string& name, RenderPart&& part);
  bool empty() const { return names_.empty(); }
  /// The merged part and its coverage. The sum is moved out: call it once (a merger is spent
  /// then: add(), add_header() and finish() throw).
  MergeReport finish();

 private:
  void check_part(const std::string& name, const RenderPart& part);
  void check_not_finished(const char* call) const;

  std::vector<std::string> names_;
  std::vector<PartInfo> infos_;
  RenderPart total_;
  bool finished_ = false;
};

/// Reads the headers of `paths`, checks them (same film, seed, integrator and scene hash; no
/// overlapping ranges), then reads and adds the parts in ascending order of their first sample
/// (one part in memory at a time besides the sum).
MergeReport merge_render_parts(const std::vector<std::string>& paths);

/// Before a merge reads its parts (`lucent merge`'s -o, Python's merge_parts output=): `output`
/// is none of them, and has a format write_merged writes and a place that can be written; throws
/// lucent::Error naming it otherwise.
void check_merge_output(const std::string& output, const std::vector<std::string>& parts);

/// After a merge: the parts' samples lie within `expect` (when given), whose ranges they miss
/// replace `report.missing`; with `complete`, none may be missing. Throws lucent::Error naming
/// the options as `expect_name` and `complete_name` ("--expect", "--complete"), and for an
/// `expect` that is empty, inverted or past 2^32.
void check_merge_coverage(MergeReport& report, const std::optional<SampleRange>& expect,
                          bool complete, const std::string& expect_name,
                          const std::string& complete_name);

/// Writes a merged part in the format of `path`'s extension: .exr (a part file, which can be
/// merged again), .png (8-bit, the parts' display settings), .pfm (the mean). Atomic.
void write_merged(const std::string& path, const RenderPart& part);

}  // namespace lucent
