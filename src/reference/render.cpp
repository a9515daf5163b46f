// The reference integrator's render loop: rows shared out to threads, every camera sample of a
// pixel taken in order, Welford's running mean and variance per pixel, non-finite samples counted
// and left out. The integrators are in integrator/, the camera in camera/, the scene's geometry,
// lights and BSDFs in geometry/, light/ and bsdf/. With integrator.caustics (path integrator),
// each row's camera samples are followed by their light paths (integrator/light_tracer.cpp), whose
// contributions each thread sums, with their squares, in its own buffers.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <thread>

#include "lucent/error.hpp"
#include "lucent/reference.hpp"
#include "lucent/types.hpp"
#include "reference/camera/camera.hpp"
#include "reference/integrator/integrator.hpp"
#include "reference/integrator/light_tracer.hpp"
#include "render/pack.hpp"
#include "render/resources.hpp"
#include "render/sample_stats.hpp"
#include "scene/loaders.hpp"
#include "scene/validate.hpp"

namespace lucent {

namespace {
// A sample counts when each component's square fits in a float (about 1.8e19 at most), as the
// kernel's do (megakernel.cl): the image's variances are floats, and a larger sample made them
// infinite (the reference wrote an EXR that compare refused); NaN and infinities fail too.
bool square_fits_float(const glm::dvec3& v) {
  const double limit = std::sqrt(double(std::numeric_limits<float>::max()));
  return std::abs(v.x) <= limit && std::abs(v.y) <= limit && std::abs(v.z) <= limit;
}
}  // namespace

RenderResult render_reference(const Scene& scene, const ReferenceOptions& options) {
  scene_detail::ScopedWarningSink sink(options.on_warning);
  scene_detail::validate_scene(scene);  // fields set directly may not have been checked
  for (const std::string& note : scene_detail::energy_gain_notes(scene)) scene_detail::warn(note);
  for (const std::string& note : scene_detail::light_notes(scene)) scene_detail::warn(note);
  for (const std::string& note : scene_detail::point_light_notes(scene)) scene_detail::warn(note);
  for (const std::string& note : scene_detail::radiance_notes(scene)) scene_detail::warn(note);
  const int W = scene.film.width, H = scene.film.height;
  if (W <= 0 || H <= 0) throw Error(scene.path + ": film size must be positive");
  // checked, not defaulted (a negative count took the scene's, or the hardware's)
  if (options.spp < 0)
    throw Error("ReferenceOptions::spp must be 0 (the scene's) or positive, got " +
                std::to_string(options.spp));
  if (options.threads < 0)
    throw Error("ReferenceOptions::threads must be 0 (the hardware's) or positive, got " +
                std::to_string(options.threads));
  const int spp = options.spp > 0 ? options.spp : scene.integrator.spp;
  if (spp <= 0) throw Error(scene.path + ": samples per pixel must be positive");
  int threads = options.threads > 0
                    ? options.threads
                    : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  threads = std::min(threads, H);
  const bool caustics = scene.integrator.caustics && scene.integrator.type == IntegratorType::Path;
  // refused before anything large is allocated, as the kernel's renders are
  render_detail::check_reference_host_memory(scene, caustics ? threads : 1);
  auto t0 = std::chrono::steady_clock::now();
  const ref::Tracer tracer(scene);
  if (tracer.world.skipped_triangles > 0)  // as pack_scene says it of the kernel's
    scene_detail::warn(scene_detail::in_file(
        scene.path, "skipped " + std::to_string(tracer.world.skipped_triangles) +
                        " degenerate or non-finite triangle(s)"));
  // its spawn offsets against the small features (a sphere of 0.5 resting on a ground sphere of
  // radius 1e11 lost its contact shadow, image-mean z +5 against the kernel in double, without a
  // word)
  if (const render_detail::SceneScale scale = render_detail::scene_scale(scene);
      ref::kSpawnOffset * scale.largest > scale.feature / 16) {
    char buf[600];
    std::snprintf(buf, sizeof buf,
                  "the reference renderer's rays leave surfaces %.0e of their coordinates away, "
                  "up to %.2g here (coordinates up to %.3g), more than 1/16 of the small features "
                  "(%.2g, the 10th percentile of primitive sizes): contacts and shadows of small "
                  "objects may be lost (a sphere of 0.5 on a ground sphere of radius 1e11 lost "
                  "its own); move the scene nearer the origin or make its large primitives smaller",
                  ref::kSpawnOffset, ref::kSpawnOffset * scale.largest, scale.largest,
                  scale.feature);
    scene_detail::warn(scene_detail::in_file(scene.path, buf));
  }
  const ref::CameraModel camera(scene);
  std::unique_ptr<ref::LightTracer> light_tracer;
  if (caustics) light_tracer = std::make_unique<ref::LightTracer>(tracer, camera);

  const size_t npix = static_cast<size_t>(W) * H;
  std::vector<double> mean(npix * 3, 0.0), m2(npix * 3, 0.0);
  std::vector<std::uint32_t> count(npix, 0);
  std::atomic<int> next_row{0};
  std::atomic<std::uint64_t> nonfinite{0}, rays{0}, light_paths{0}, launched{0};
  std::atomic<bool> cancelled{false};
  // per thread: the sum and the sum of squares of the light paths' values per pixel and channel
  // (a light path's value at a pixel: the sum of its connections' shares there)
  std::vector<std::vector<double>> light_sum(caustics ? threads : 0),
      light_sq(caustics ? threads : 0);
  // per thread: the sums of the light paths' totals (a path's shares over all pixels) and of
  // their squares, for the image mean's light part (RenderResult::light_mean_variance)
  std::vector<render_detail::LightTotals> light_totals(caustics ? threads : 0);

  auto worker = [&](int thread) {
    ref::reset_ray_count();
    std::uint64_t my_nonfinite = 0, my_paths = 0, my_launched = 0;
    std::vector<ref::Splat> splats;
    if (caustics) {
      light_sum[thread].assign(npix * 3, 0.0);
      light_sq[thread].assign(npix * 3, 0.0);
    }
    // checked before every sample: a pixel of many samples took seconds, and a row of them
    // minutes (Ctrl-C waited for the row)
    auto stop = [&] {
      if (options.cancel && options.cancel->load(std::memory_order_relaxed)) cancelled = true;
      return cancelled.load(std::memory_order_relaxed);
    };
    for (int y; !stop() && (y = next_row.fetch_add(1)) < H;) {
      for (int x = 0; x < W; ++x) {
        const size_t i = static_cast<size_t>(y) * W + x;
        for (int k = 0; k < spp && !stop(); ++k) {
          ref::Sampler rng{static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(k),
                           scene.integrator.seed, scene.integrator.sampler};
          glm::dvec3 v = ref::radiance(tracer, camera.ray(x, y, rng), rng);
          ++my_launched;
          if (!square_fits_float(v)) {
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
      if (!caustics) continue;
      // the row's light paths: one per camera sample, with that sample's random numbers
      for (int x = 0; x < W; ++x)
        for (int k = 0; k < spp && !stop(); ++k) {
          ref::Sampler rng{static_cast<std::uint32_t>(static_cast<size_t>(y) * W + x),
                           static_cast<std::uint32_t>(k), scene.integrator.seed,
                           scene.integrator.sampler};
          splats.clear();
          light_tracer->trace(rng, splats);
          ++my_paths;
          // a share whose square does not fit a float is left out and counted
          const auto kept = std::remove_if(splats.begin(), splats.end(), [](const ref::Splat& sp) {
            return !square_fits_float(sp.c);
          });
          my_nonfinite += static_cast<std::uint64_t>(splats.end() - kept);
          splats.erase(kept, splats.end());
          // The path's value at a pixel is the sum X of its shares there, one per connection
          // whose filter reaches the pixel (a path connects at every non-delta vertex from y_2
          // on, and wide filters or small films put several of them in one pixel): the sum of
          // squares takes X^2, cross terms included. Grouped by pixel in their order, so that
          // each pixel's sum adds the same shares in the same order as one by one.
          std::stable_sort(
              splats.begin(), splats.end(),
              [](const ref::Splat& a, const ref::Splat& b) { return a.pixel < b.pixel; });
          glm::dvec3 total(0.0);
          for (size_t g = 0; g < splats.size();) {
            const int pixel = splats[g].pixel;
            glm::dvec3 X(0.0);
            for (; g < splats.size() && splats[g].pixel == pixel; ++g) {
              X += splats[g].c;
              for (int c = 0; c < 3; ++c) light_sum[thread][pixel * 3 + c] += splats[g].c[c];
            }
            for (int c = 0; c < 3; ++c) light_sq[thread][pixel * 3 + c] += X[c] * X[c];
            total += X;
          }
          for (int c = 0; c < 3; ++c) {
            light_totals[thread].sum[c] += total[c];
            light_totals[thread].sumsq[c] += total[c] * total[c];
          }
        }
    }
    rays += ref::ray_count();
    nonfinite += my_nonfinite;
    light_paths += my_paths;
    launched += my_launched;
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker, t);
  worker(0);
  for (auto& t : pool) t.join();

  // light tracing: pixel value = camera mean + sum_c / N; the variance of one camera sample gets
  // n times the light paths' variance of their mean, (sum c^2 / N - (sum c / N)^2) / (N - 1), so
  // that variance / n stays the variance of the pixel's mean. N counts the light paths traced
  // (all N = W H spp unless cancelled); pixels without camera samples stay empty.
  const double N = static_cast<double>(light_paths);
  for (size_t t = 1; t < light_sum.size(); ++t) {
    for (size_t j = 0; j < npix * 3; ++j) {
      light_sum[0][j] += light_sum[t][j];
      light_sq[0][j] += light_sq[t][j];
    }
    for (int c = 0; c < 3; ++c) {
      light_totals[0].sum[c] += light_totals[t].sum[c];
      light_totals[0].sumsq[c] += light_totals[t].sumsq[c];
    }
  }

  RenderResult r;
  r.mean = Image{W, H, std::vector<float>(npix * 3)};
  r.variance = Image{W, H, std::vector<float>(npix * 3)};
  LightMeanVariance lmv;  // the image mean's light part (its variances)
  for (size_t i = 0; i < npix; ++i)
    for (int c = 0; c < 3; ++c) {
      double m = mean[i * 3 + c], var = count[i] > 1 ? m2[i * 3 + c] / (count[i] - 1) : 0.0;
      if (caustics && N > 0 && count[i] > 0) {
        const double lm = light_sum[0][i * 3 + c] / N;
        m += lm;
        if (N > 1) {
          const double lvar = std::max(0.0, light_sq[0][i * 3 + c] / N - lm * lm) / (N - 1);
          var += count[i] * lvar;
          // var / n holds it, where compare reads var (a pixel of n < 2 counts 0 there)
          if (count[i] >= 2) lmv.pixels[c] += lvar / (double(npix) * double(npix));
        }
      }
      r.mean.rgb[i * 3 + c] = static_cast<float>(m);
      r.variance.rgb[i * 3 + c] = static_cast<float>(var);
    }
  if (caustics && N > 1) {
    render_detail::light_paths_variance(light_totals[0], light_paths, double(npix), lmv.paths);
    r.light_mean_variance = render_detail::finite_or_none(lmv);
  }
  r.samples = std::move(count);
  // stopped: the samples launched per pixel on average, rounded down (it said the spp asked
  // for, also when it stopped before any sample)
  r.spp = cancelled ? launched / npix : static_cast<std::uint64_t>(spp);
  r.nonfinite = nonfinite;
  r.rays = rays;
  r.cancelled = cancelled;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.device = "reference (" + std::to_string(threads) + " thread" + (threads > 1 ? "s" : "") + ")";
  r.seed = scene.integrator.seed;
  r.sampler = type_name(scene.integrator.sampler);
  return r;
}

}  // namespace lucent
