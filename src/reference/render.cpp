// The reference integrator's render loop: rows shared out to threads, every camera sample of a
// pixel taken in order, Welford's running mean and variance per pixel, non-finite samples counted
// and left out. The integrators are in integrator/, the camera in camera/, the scene's geometry,
// lights and BSDFs in geometry/, light/ and bsdf/.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "lucent/error.hpp"
#include "lucent/reference.hpp"
#include "reference/camera/camera.hpp"
#include "reference/integrator/integrator.hpp"

namespace lucent {

RenderResult render_reference(const Scene& scene, const ReferenceOptions& options) {
  const int W = scene.film.width, H = scene.film.height;
  if (W <= 0 || H <= 0) throw Error(scene.path + ": film size must be positive");
  const int spp = options.spp > 0 ? options.spp : scene.integrator.spp;
  if (spp <= 0) throw Error(scene.path + ": samples per pixel must be positive");
  auto t0 = std::chrono::steady_clock::now();
  const ref::Tracer tracer(scene);
  const ref::CameraModel camera(scene);

  const size_t npix = static_cast<size_t>(W) * H;
  std::vector<double> mean(npix * 3, 0.0), m2(npix * 3, 0.0);
  std::vector<std::uint32_t> count(npix, 0);
  std::atomic<int> next_row{0};
  std::atomic<std::uint64_t> nonfinite{0}, rays{0};
  std::atomic<bool> cancelled{false};

  auto worker = [&]() {
    ref::reset_ray_count();
    std::uint64_t my_nonfinite = 0;
    for (int y; (y = next_row.fetch_add(1)) < H;) {
      if (options.cancel && options.cancel->load()) {
        cancelled = true;
        break;
      }
      for (int x = 0; x < W; ++x) {
        const size_t i = static_cast<size_t>(y) * W + x;
        for (int k = 0; k < spp; ++k) {
          ref::Sampler rng{static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(k),
                           scene.integrator.seed, scene.integrator.sampler};
          glm::dvec3 v = ref::radiance(tracer, camera.ray(x, y, rng), rng);
          if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
            ++my_nonfinite;
            continue;
          }
          // Welford's running mean and sum of squared deviations
          double n = ++count[i];
          for (int c = 0; c < 3; ++c) {
            double d = v[c] - mean[i * 3 + c];
            mean[i * 3 + c] += d / n;
            m2[i * 3 + c] += d * (v[c] - mean[i * 3 + c]);
          }
        }
      }
    }
    rays += ref::ray_count();
    nonfinite += my_nonfinite;
  };
  int threads = options.threads > 0
                    ? options.threads
                    : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  threads = std::min(threads, H);
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();

  RenderResult r;
  r.mean = Image{W, H, std::vector<float>(npix * 3)};
  r.variance = Image{W, H, std::vector<float>(npix * 3)};
  for (size_t i = 0; i < npix; ++i)
    for (int c = 0; c < 3; ++c) {
      r.mean.rgb[i * 3 + c] = static_cast<float>(mean[i * 3 + c]);
      r.variance.rgb[i * 3 + c] =
          static_cast<float>(count[i] > 1 ? m2[i * 3 + c] / (count[i] - 1) : 0.0);
    }
  r.samples = std::move(count);
  r.spp = static_cast<std::uint64_t>(spp);
  r.nonfinite = nonfinite;
  r.rays = rays;
  r.cancelled = cancelled;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.device = "reference (" + std::to_string(threads) + " thread" + (threads > 1 ? "s" : "") + ")";
  return r;
}

}  // namespace lucent
