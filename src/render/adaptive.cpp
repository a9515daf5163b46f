// Adaptive sampling: planning the halves' sample counts and combining them (adaptive.hpp).
#include "render/adaptive.hpp"

#include <algorithm>
#include <cmath>

#include "render/sample_stats.hpp"

namespace lucent::render_detail {

std::vector<double> neighbour_values(const std::vector<double>& mean,
                                     const std::vector<std::uint32_t>& present, int width,
                                     int height, const std::vector<double>* add) {
  const std::size_t npix = static_cast<std::size_t>(width) * height;
  std::vector<double> v(npix * 3, 0.0);
  if (mean.size() < npix * 3 || present.size() < npix) return v;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width + x;
      double s[3] = {0, 0, 0};
      int k = 0;
      for (int yy = std::max(0, y - 1); yy <= std::min(height - 1, y + 1); ++yy)
        for (int xx = std::max(0, x - 1); xx <= std::min(width - 1, x + 1); ++xx) {
          const std::size_t j = static_cast<std::size_t>(yy) * width + xx;
          if (j == i || present[j] == 0) continue;
          ++k;
          for (int c = 0; c < 3; ++c) s[c] += mean[j * 3 + c];
        }
      for (int c = 0; c < 3; ++c) {
        const double own = mean[i * 3 + c];
        v[i * 3 + c] = (k ? std::min(own, s[c] / k) : own) + (add ? (*add)[i * 3 + c] : 0.0);
      }
    }
  return v;
}

std::vector<double> sample_means(const std::vector<double>& sum,
                                 const std::vector<std::uint32_t>& count) {
  std::vector<double> m(count.size() * 3, 0.0);
  for (std::size_t i = 0; i < count.size(); ++i)
    if (count[i] > 0)
      for (int c = 0; c < 3; ++c) m[i * 3 + c] = sum[i * 3 + c] / count[i];
  return m;
}

std::vector<double> relative_variance(const std::vector<double>& sum,
                                      const std::vector<double>& sumsq,
                                      const std::vector<std::uint32_t>& count,
                                      const std::vector<double>* value) {
  std::vector<double> v(count.size(), 0.0);
  for (std::size_t i = 0; i < count.size(); ++i) {
    const double n = count[i];
    if (n < 2) continue;
    double r = 0;
    for (int c = 0; c < 3; ++c) {
      const double var = sample_variance(sum[i * 3 + c], sumsq[i * 3 + c], n);
      const double val = value ? (*value)[i * 3 + c] : sum[i * 3 + c] / n;
      r += var / (val * val + 0.01);
    }
    v[i] = r / 3;
  }
  return v;
}

std::vector<double> light_means(const std::vector<double>& light_sum, std::uint64_t paths,
                                int width, int height) {
  std::vector<double> m(light_sum.size(), 0.0);
  if (paths == 0 || light_sum.size() != static_cast<std::size_t>(width) * height * 3) return m;
  const double N = double(paths);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double s[3] = {0, 0, 0};
      int k = 0;
      for (int yy = std::max(0, y - 1); yy <= std::min(height - 1, y + 1); ++yy)
        for (int xx = std::max(0, x - 1); xx <= std::min(width - 1, x + 1); ++xx, ++k)
          for (int c = 0; c < 3; ++c) s[c] += light_sum[(std::size_t(yy) * width + xx) * 3 + c];
      for (int c = 0; c < 3; ++c) m[(std::size_t(y) * width + x) * 3 + c] = s[c] / (k * N);
    }
  return m;
}

double light_relative_variance(const std::vector<double>& light_sum,
                               const std::vector<double>& light_sumsq, std::uint64_t paths,
                               const std::vector<double>& value) {
  const std::size_t npix = value.size() / 3;
  if (paths < 2 || npix == 0 || light_sum.size() < npix * 3) return 0;
  const double N = double(paths);
  double total = 0;
  for (std::size_t k = 0; k < npix * 3; ++k) {
    const double s2 = sample_variance(light_sum[k], light_sumsq[k], N);
    total += s2 / (value[k] * value[k] + 0.01);
  }
  return total / (3.0 * double(npix));
}

std::vector<double> raised_variance(const std::vector<double>& v, int width, int height,
                                    int radius) {
  const std::size_t npix = static_cast<std::size_t>(width) * height;
  std::vector<double> r(npix, 0.0);
  if (v.size() < npix) return r;
  // per row: each column's sum over the window's rows, then those sums over the window's columns
  std::vector<double> col(width);
  for (int y = 0; y < height; ++y) {
    const int y0 = std::max(0, y - radius), y1 = std::min(height - 1, y + radius);
    for (int x = 0; x < width; ++x) {
      double s = 0;
      for (int yy = y0; yy <= y1; ++yy) s += v[static_cast<std::size_t>(yy) * width + x];
      col[x] = s;
    }
    for (int x = 0; x < width; ++x) {
      const int x0 = std::max(0, x - radius), x1 = std::min(width - 1, x + radius);
      double s = 0;
      for (int xx = x0; xx <= x1; ++xx) s += col[xx];
      const double k = double(x1 - x0 + 1) * double(y1 - y0 + 1);
      const std::size_t i = static_cast<std::size_t>(y) * width + x;
      r[i] = std::max(v[i], s / k);
    }
  }
  return r;
}

int choose_radius(const Pilot& o, const Pilot& c, int width, int height, double* under) {
  const int radii[] = {1, 2, 3, 5};
  if (under) *under = 0;
  const std::size_t n = c.pixels.size();
  if (o.value.size() < n * 3 || c.count.size() < n || c.sum.size() < n * 3 || n == 0) return 1;
  // C's relative variances, weighed by o's neighbour values at C's pixels
  const std::vector<double> vc = relative_variance(c.sum, c.sumsq, c.count, &o.value);
  double u = 0;
  for (int R : radii) {
    const std::vector<double> r = raised_variance(o.v, width, height, R);
    double num = 0, den = 0;
    for (std::size_t j = 0; j < n; ++j) {
      const std::size_t i = c.pixels[j];
      if (i >= r.size() || !(r[i] > 0) || c.count[j] < 2) continue;
      const double s = std::sqrt(r[i]);
      num += vc[j] / s;
      den += s;
    }
    u = den > 0 ? num / den : 0;
    if (under) *under = u;
    if (u <= 1.1) return R;
  }
  return radii[3];
}

SamplePlan plan_samples(const std::vector<double>& v, int width, int height, double target,
                        double budget, std::uint32_t min_n, std::uint32_t max_n, double gain,
                        double light_w, int radius) {
  const std::size_t npix = static_cast<std::size_t>(width) * height;
  max_n = std::max(max_n, min_n);
  // the shape: sqrt of the larger of the pixel's variance and its neighbourhood's mean
  std::vector<double> shape = raised_variance(v, width, height, radius);
  for (double& x : shape) x = std::sqrt(x);
  double smallest = 0;
  for (double s : shape)
    if (s > 0 && (smallest == 0 || s < smallest)) smallest = s;
  // the allocation's shape: the camera term's, or an even one when only the light term (which
  // reads the total count alone) has variance
  const bool light_only = smallest == 0 && light_w > 0;
  std::vector<double> alloc = light_only ? std::vector<double>(npix, 1.0) : shape;
  if (light_only) smallest = 1;
  SamplePlan plan;
  plan.counts.assign(npix, min_n);
  auto fill = [&](double lambda) {
    double predicted = 0, total = 0;
    for (std::size_t i = 0; i < npix; ++i) {
      const double want = std::ceil(lambda * alloc[i]);
      const std::uint32_t n =
          want >= max_n ? max_n : std::max(min_n, static_cast<std::uint32_t>(std::max(0.0, want)));
      plan.counts[i] = n;
      predicted += shape[i] * shape[i] / n;  // the smoothed variance: see plan_samples' doc
      total += n;
    }
    plan.light = total > 0 ? light_w / total : 0;
    plan.predicted = npix ? gain * predicted / double(npix) + plan.light : 0;
    plan.mean = npix ? total / double(npix) : 0;
  };
  // reaching the goal is monotone in lambda: bisect on log(lambda) between "every count at
  // min_n" and "every count at max_n"
  auto reached = [&](double lambda) {
    fill(lambda);
    return target > 0 ? plan.predicted <= target : plan.mean <= budget;
  };
  double lo = 0, hi = 0;  // lambdas; 0 gives min_n everywhere
  if (smallest == 0) {    // no variance anywhere: nothing to adapt to
    fill(0);
    return plan;
  }
  hi = double(max_n) / smallest * 2;  // every count at max_n
  if (target > 0) {
    if (reached(0)) return plan;    // the pilot-sized plan already predicts the target
    if (!reached(hi)) return plan;  // unreachable: every count at max_n
    lo = 1e-30 * hi;                // not reached there (counts at min_n)
    for (int it = 0; it < 200 && hi / lo > 1 + 1e-9; ++it) {
      const double mid = std::sqrt(lo * hi);
      (reached(mid) ? hi : lo) = mid;
    }
    fill(hi);  // the smallest lambda found that reaches it
  } else {
    if (!reached(0)) return plan;  // even min_n everywhere is over the budget
    if (reached(hi)) return plan;  // max_n everywhere fits
    lo = 1e-30 * hi;
    for (int it = 0; it < 200 && hi / lo > 1 + 1e-9; ++it) {
      const double mid = std::sqrt(lo * hi);
      (reached(mid) ? lo : hi) = mid;
    }
    fill(lo);  // the largest lambda found within the budget
  }
  return plan;
}

Calibration calibrate_model(const std::vector<double>& o_sum, const std::vector<double>& o_sumsq,
                            const std::vector<std::uint32_t>& o_count,
                            const std::vector<double>& c_sum, const std::vector<double>& c_sumsq,
                            const std::vector<std::uint32_t>& c_count, double lo, double hi) {
  Calibration cal;
  for (std::size_t i = 0; i < c_count.size() && i < o_count.size(); ++i) {
    const double no = o_count[i], nc = c_count[i];
    if (no < 2 || nc < 2) continue;
    ++cal.pixels;
    for (int c = 0; c < 3; ++c) {
      const std::size_t k = i * 3 + c;
      const double mo = o_sum[k] / no, mc = c_sum[k] / nc, value = 0.5 * (mo + mc);
      const double w = 1 / (value * value + 0.01);
      // one sample's variance pooled over O and C
      const double s2 = pooled_variance(o_sum[k], o_sumsq[k], no, c_sum[k], c_sumsq[k], nc);
      cal.measured += w * (mo - mc) * (mo - mc) / 2;
      cal.modelled += w * s2 * (1 / no + 1 / nc) / 2;
    }
  }
  if (cal.modelled > 0)
    cal.gain = std::clamp(cal.measured / cal.modelled, lo, hi);
  else
    cal.gain = cal.measured > 0 ? hi : 1;  // no variance seen: nothing to scale
  return cal;
}

HalfPlans plan_halves(const Pilot& a, const Pilot& b, const Pilot& c, int width, int height,
                      double target, double budget, std::uint32_t min_n, std::uint32_t max_n) {
  HalfPlans out;
  const Pilot* other[2] = {&b, &a};
  for (int h = 0; h < 2; ++h) {
    const Pilot& o = *other[h];
    if (target > 0) {
      out.calib[h] = calibrate_model(o.sum, o.sumsq, o.count, c.sum, c.sumsq, c.count);
      if (out.calib[h].pixels < kMinCalibrationPixels) out.calib[h].gain = 1;
      out.radius[h] = choose_radius(o, c, width, height, &out.under[h]);
    }
    out.plan[h] = plan_samples(o.v, width, height, 2 * target, budget / 2, min_n, max_n,
                               out.calib[h].gain, o.light_w, out.radius[h]);
  }
  return out;
}

int calibration_stride(int width, int height, std::size_t min_pixels) {
  for (int s = 4; s > 1; --s) {
    const std::size_t n =
        static_cast<std::size_t>((width + s - 1 - s / 2) / s) * ((height + s - 1 - s / 2) / s);
    if (n >= min_pixels) return s;
  }
  return 1;
}

double halves_relmse(const std::vector<double>& sum_a, const std::vector<std::uint32_t>& n_a,
                     const std::vector<double>& sum_b, const std::vector<std::uint32_t>& n_b,
                     const std::vector<double>* value) {
  double total = 0;
  std::size_t pixels = 0;
  for (std::size_t i = 0; i < n_a.size() && i < n_b.size(); ++i) {
    if (n_a[i] == 0 || n_b[i] == 0) continue;
    ++pixels;
    for (int c = 0; c < 3; ++c) {
      const double a = sum_a[i * 3 + c] / n_a[i], b = sum_b[i * 3 + c] / n_b[i];
      const double val = value ? (*value)[i * 3 + c] : 0.5 * (a + b);
      total += (a - b) * (a - b) / 4 / (val * val + 0.01);
    }
  }
  return pixels ? total / (3.0 * double(pixels)) : 0;
}

void combine_halves(const double* sum_a, const double* sumsq_a, std::uint32_t n_a,
                    const double* sum_b, const double* sumsq_b, std::uint32_t n_b, float mean[3],
                    float var[3], std::uint32_t* n, double half_var[2][3]) {
  *n = n_a + n_b;
  for (int c = 0; c < 3; ++c) {
    const double ma = n_a ? sum_a[c] / n_a : 0, mb = n_b ? sum_b[c] / n_b : 0;
    double m = n_a && n_b ? 0.5 * (ma + mb) : (n_a ? ma : mb);
    // one sample's variance from both halves: only where a half has no degree of freedom of its
    // own. One sample in each half (a render stopped by --time in its pilot): their two
    // samples' variance, the halves estimating one mean (it was 0, which claimed every pixel
    // exact)
    const double s2 = n_a == 1 && n_b == 1
                          ? sample_variance(sum_a[c] + sum_b[c], sumsq_a[c] + sumsq_b[c], 2)
                          : pooled_variance(sum_a[c], sumsq_a[c], n_a, sum_b[c], sumsq_b[c], n_b);
    // each half's variance of one sample from its own samples: half A's count was planned from
    // B's pilot, so a variance pooled over both halves reads B's pilot samples, which are
    // correlated with n_A (a pilot that missed the bright paths plans few samples and lowers the
    // pooled variance exactly where s^2 / n_A is large): var / n was 0.74-0.91 of the mean's
    // variance (render/adaptive.hpp). A half's own variance is independent of its count.
    const double sa = n_a >= 2 ? sample_variance(sum_a[c], sumsq_a[c], n_a) : s2;
    const double sb = n_b >= 2 ? sample_variance(sum_b[c], sumsq_b[c], n_b) : s2;
    const double va = n_a ? sa / n_a : 0, vb = n_b ? sb / n_b : 0;  // of each half's mean
    // the variance of the mean: (va + vb) / 4 for the average, the one half's alone otherwise
    const double v = n_a && n_b ? double(*n) * (va + vb) / 4 : double(*n) * (va + vb);
    if (half_var) half_var[0][c] = va, half_var[1][c] = vb;
    mean[c] = static_cast<float>(m);
    var[c] = static_cast<float>(v);
  }
}

void add_light_halves(const double* lsum_a, const double* lsumsq_a, std::uint64_t paths_a,
                      const double* lsum_b, const double* lsumsq_b, std::uint64_t paths_b,
                      std::uint32_t n, float mean[3], float var[3], double light_var[3]) {
  for (int c = 0; c < 3; ++c) {
    double m[2] = {0, 0}, v[2] = {0, 0};
    const double* ls[2] = {lsum_a, lsum_b};
    const double* lq[2] = {lsumsq_a, lsumsq_b};
    const std::uint64_t np[2] = {paths_a, paths_b};
    for (int h = 0; h < 2; ++h) {
      if (np[h] == 0) continue;
      const double N = double(np[h]);
      m[h] = ls[h][c] / N;
      // the variance of the half's light estimate: one path's variance over N
      v[h] = sample_variance(ls[h][c], lq[h][c], N) / N;
    }
    const bool both = paths_a > 0 && paths_b > 0;
    const double lm = both ? 0.5 * (m[0] + m[1]) : m[0] + m[1];
    const double lv = both ? (v[0] + v[1]) / 4 : v[0] + v[1];
    light_var[c] = lv;
    mean[c] = static_cast<float>(double(mean[c]) + lm);
    var[c] = static_cast<float>(double(var[c]) + double(n) * lv);
  }
}

}  // namespace lucent::render_detail
