// Parts of a session's render (lucent/parts.hpp): the header and the part a Renderer makes, and
// the scenes part files cannot hold. Apart from parts.cpp (the part file's format, reading and
// merge), which then needs no OpenCL session: the fuzz target of part files links it alone.
#include "lucent/error.hpp"
#include "lucent/parts.hpp"
#include "lucent/session.hpp"
#include "lucent/types.hpp"
#include "lucent/version.hpp"
#include "render/pack.hpp"

namespace lucent {

void check_part_scene(const Scene& scene, const std::string& scene_path) {
  // (caustics asked for in a scene without a mirror or smooth glass render none: such a scene's
  // parts, checkpoints and MPI ranks were refused all the same)
  if (render_detail::light_traced_caustics(scene))
    throw Error(scene_path +
                ": integrator.caustics: part files and MPI ranks cannot hold light-traced "
                "caustics yet; render this scene in one process, or without caustics");
}

PartInfo part_header(const Renderer& renderer, const SampleRange& requested,
                     const std::string& scene_path) {
  check_part_scene(renderer.scene(), scene_path);
  const Scene& scene = renderer.scene();
  PartInfo info;
  info.width = scene.film.width;
  info.height = scene.film.height;
  info.scene_hash = renderer.image_hash();
  info.seed = scene.integrator.seed;
  info.sampler = type_name(scene.integrator.sampler);
  info.integrator = type_name(scene.integrator.type);
  info.version = kVersion;
  info.scene = scene_path;
  info.requested = {requested};
  // (a range to 2^64 made a part file that reading refused)
  if (requested.end <= requested.begin || requested.end > (1ull << 32))
    throw Error("make_part: requested samples " + range_text(requested) +
                ": need 0 <= A < B <= 4294967296");
  info.display = DisplaySettings{scene.film.transfer, scene.film.gamma, scene.film.exposure,
                                 scene.film.tonemap};
  return info;
}

RenderPart make_part(const Renderer& renderer, const SampleRange& requested,
                     const std::string& scene_path) {
  RenderPart p;
  p.info = part_header(renderer, requested, scene_path);
  p.acc = renderer.accumulation();
  PartInfo& info = p.info;
  info.width = p.acc.width;  // (the session's film: its scene's)
  info.height = p.acc.height;
  if (p.acc.spp > 0) info.samples = {{p.acc.first_sample, p.acc.first_sample + p.acc.spp}};
  // (requested is one range: the samples, none or one range, lie within it)
  if (!info.samples.empty() &&
      (info.samples.front().begin < requested.begin || info.samples.front().end > requested.end))
    throw Error("make_part: the session's samples " + ranges_text(info.samples) +
                " lie outside the requested " + range_text(requested));
  info.nonfinite = p.acc.nonfinite;
  info.rays = p.acc.rays;
  info.seconds = p.acc.seconds;
  return p;
}

}  // namespace lucent
