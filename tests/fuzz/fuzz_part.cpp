// Fuzz target: part files and checkpoints (an OpenEXR with the lucent.* header attributes and the
// sums' UINT channels, docs/parts.md), from the file's bytes, through what reads them:
// read_part_info (`lucent merge`'s header pass, a checkpoint's read()), read_render_part,
// read_render (`lucent compare` reads a part from its sums), and what follows a read: the merge
// of `lucent merge` (merge_render_parts, check_merge_coverage, write_merged) and of a checkpoint
// (PartMerger: the session's part, then the checkpoint's). The second part of each merge is the
// part read, written again with its sample ranges moved past its own.
// Checks: a part read whole has the header read alone; compare's image is the part's; a merge
// holds both parts' samples and counts; a merged part written reads back as it was.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "fuzz_common.hpp"
#include "image/image_probe.hpp"
#include "lucent/error.hpp"
#include "lucent/parts.hpp"

namespace {

using lucent::PartInfo;
using lucent::RenderPart;
using lucent::SampleRange;
using lucent::fuzz::check;

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * 8) == 0);
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * 4) == 0);
}

bool same_header(const PartInfo& a, const PartInfo& b) {
  return a.width == b.width && a.height == b.height && a.scene_hash == b.scene_hash &&
         a.seed == b.seed && a.sampler == b.sampler && a.integrator == b.integrator &&
         a.version == b.version && a.scene == b.scene && a.samples == b.samples &&
         a.requested == b.requested && a.nonfinite == b.nonfinite && a.rays == b.rays &&
         a.display.transfer == b.display.transfer && a.display.tonemap == b.display.tonemap &&
         a.display.gamma == b.display.gamma && a.display.exposure == b.display.exposure;
}

/// Whether the OpenEXR header of `data` has the attribute lucent.checksum.
bool has_checksum(const std::uint8_t* data, std::size_t size, const std::string& path) {
  EXRHeader header;
  lucent::image_detail::probe_exr(data, size, path, lucent::image_detail::kMaxImagePixels, header);
  const bool has = lucent::image_detail::exr_string_attributes(header).count("lucent.checksum") > 0;
  FreeEXRHeader(&header);
  return has;
}

/// `p` with its ranges moved up by `by` (the caller checks that they stay below 2^32).
RenderPart shifted(const RenderPart& p, std::uint64_t by) {
  RenderPart q = p;
  for (auto* list : {&q.info.samples, &q.info.requested})
    for (SampleRange& r : *list) r = {r.begin + by, r.end + by};
  return q;
}

/// The merged part, written as `lucent merge -o X.exr` writes it, reads back as it was (the
/// writer may refuse it: a sum that overflowed, a time that did).
void check_round_trip(const std::string& path, const RenderPart& merged) {
  try {
    lucent::write_merged(path, merged);
  } catch (const lucent::Error&) {
    return;
  }
  const RenderPart back = lucent::read_render_part(path);
  check(same_header(back.info, merged.info), "a merged part read back has another header");
  // the time: written with six decimals
  check(std::fabs(back.info.seconds - merged.info.seconds) <=
            std::max(1e-6, 1e-15 * merged.info.seconds),
        "a merged part read back has another time");
  check(same_bits(back.acc.sum, merged.acc.sum) && same_bits(back.acc.sumsq, merged.acc.sumsq) &&
            back.acc.count == merged.acc.count,
        "a merged part read back has other sums or counts");
}

void merges(const std::string& dir, const std::string& path, const RenderPart& p) {
  // the second part: the same image's samples after the part's requested ones
  const std::uint64_t by = p.info.requested.back().end;
  if (p.info.requested.back().end + by > (std::uint64_t(1) << 32)) return;
  const RenderPart q = shifted(p, by);
  const std::string qpath = dir + "/q.exr";
  try {
    lucent::write_render_part(qpath, q);
  } catch (const lucent::Error&) {
    check(false, "a part that was read cannot be written again");
  }
  const std::size_t npix = p.acc.count.size();
  // lucent merge (and lucent-mpi's rank 0, and Python's merge_parts)
  try {
    lucent::MergeReport r = lucent::merge_render_parts({qpath, path});
    check(r.order.size() == 2 && r.order[0] == path, "merge order is not by first sample");
    check(r.merged.acc.count.size() == npix, "merged film size");
    for (std::size_t i = 0; i < npix; ++i)
      check(r.merged.acc.count[i] == 2 * p.acc.count[i], "merged counts are not the sum");
    check(r.merged.info.nonfinite == 2 * p.info.nonfinite, "merged non-finite count");
    lucent::check_merge_coverage(r, SampleRange{0, 2 * by}, false, "--expect", "--complete");
    check_round_trip(dir + "/merged.exr", r.merged);
    try {
      lucent::write_merged(dir + "/merged.pfm", r.merged);
    } catch (const lucent::Error&) {
    }
  } catch (const lucent::Error&) {
    // the sums of two finite parts may overflow (refused with a message)
  }
  // a checkpoint's resumption (cli/checkpoint.cpp, Checkpoint::whole): the session's part, moved
  // in, then the checkpoint's
  try {
    lucent::PartMerger m;
    m.add("session", RenderPart(q));
    m.add(path, p);
    const lucent::MergeReport r = m.finish();
    check(r.merged.info.samples.size() >= 1 &&
              r.merged.info.samples.front().begin == p.info.samples.front().begin,
          "a checkpoint's merge lost its samples");
  } catch (const lucent::Error&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  lucent::fuzz::Bundle b;
  b.main.assign(reinterpret_cast<const char*>(data), size);
  const std::string dir = lucent::fuzz::write_bundle(b, "part.exr");
  const std::string path = dir + "/part.exr";
  for (const char* f : {"/q.exr", "/merged.exr", "/merged.pfm"}) std::remove((dir + f).c_str());
  bool header_ok = false;
  PartInfo info;
  try {
    info = lucent::read_part_info(path);
    header_ok = true;
  } catch (const lucent::Error&) {
  }
  // compare's reader (a part's image from its sums; other renders' attributes too)
  std::optional<lucent::RenderResult> compared;
  try {
    compared = lucent::image_detail::read_render_memory(data, size, path);
  } catch (const lucent::Error&) {
  }
  RenderPart p;
  try {
    p = lucent::read_render_part(path);
  } catch (const lucent::Error&) {
    return 0;
  }
  check(header_ok && same_header(info, p.info),
        "read_render_part took a part whose header "
        "read_part_info refused or read otherwise");
  const std::size_t npix = static_cast<std::size_t>(p.info.width) * p.info.height;
  check(npix > 0 && p.acc.width == p.info.width && p.acc.height == p.info.height &&
            p.acc.sum.size() == npix * 3 && p.acc.sumsq.size() == npix * 3 &&
            p.acc.count.size() == npix,
        "part sizes");
  check(!p.info.samples.empty() || p.info.nonfinite == 0, "a part of no samples");
  const lucent::RenderResult shown = lucent::part_result(p);
  // compare shows a part with a checksum from its sums (older part files, without one, from their
  // display channels: docs/compare.md)
  check(!compared || !has_checksum(data, size, path) ||
            (same_bits(compared->mean.rgb, shown.mean.rgb) &&
             same_bits(compared->variance.rgb, shown.variance.rgb) &&
             compared->samples == shown.samples),
        "read_render's image of a part differs from the part's");
  if (!p.info.samples.empty()) merges(dir, path, p);
  return 0;
}
