#include "sim/internal/speckle_matcher.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/internal/counter_random.h"

namespace mmh::sim::internal {
namespace {

// A uniform in [0, 1) from 53 bits of a 64-bit hash.
double Uniform(uint64_t h) { return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0); }

// x^n for a whole n >= 0 by repeated squaring (std::pow costs about 20 times more per pixel).
float WholePower(float x, int n) {
  float result = 1.0f;
  while (n > 0) {
    if (n & 1) result *= x;
    x *= x;
    n >>= 1;
  }
  return result;
}

// Pixels are matched in segments of this many columns: each segment scores only the integer
// disparities its windows' rendered disparities can reach.
constexpr int kSegment = 64;

}  // namespace

SpeckleMatcher::SpeckleMatcher(const StructuredLightOptions& options, int width, int height,
                               double max_disparity)
    : options_(options), width_(width), height_(height), radius_(options.window_px / 2) {
  max_d_ = static_cast<int>(std::ceil(max_disparity)) + options.search_px + 2;
  x_min_ = -max_d_ - radius_ - 2;
  const int x_max = width + radius_ + 2;
  columns_ = x_max - x_min_ + 1;
  samples_ = columns_ * kSubsamples + 1;
  pattern_.assign(static_cast<size_t>(height) * samples_, 0.0f);

  // Dots at random positions over the pattern's extent (plus a margin for their tails), each a
  // Gaussian of dot_sigma_px with a brightness uniform in [0.5, 1]; added in dot order, so the
  // pattern is the same on every machine and thread count.
  const double sigma = options.dot_sigma_px;
  const double reach = 3.0 * sigma;
  const double x0 = x_min_ - reach, x1 = x_max + reach;
  const double y0 = -reach, y1 = height + reach;
  const auto dots = static_cast<uint64_t>(std::llround(options.dot_density * (x1 - x0) * (y1 - y0)));
  const double inverse_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
  for (uint64_t i = 0; i < dots; ++i) {
    const uint64_t key = Mix64(options.pattern_seed ^ Mix64(3 * i + 0x9E3779B97F4A7C15ULL));
    const double x = x0 + (x1 - x0) * Uniform(key);
    const double y = y0 + (y1 - y0) * Uniform(Mix64(key + 1));
    const double brightness = 0.5 + 0.5 * Uniform(Mix64(key + 2));
    const int row_first = std::max(0, static_cast<int>(std::ceil(y - reach)));
    const int row_last = std::min(height - 1, static_cast<int>(std::floor(y + reach)));
    const int k_first = std::max(0, static_cast<int>(std::ceil((x - reach - x_min_) * kSubsamples)));
    const int k_last =
        std::min(samples_ - 1, static_cast<int>(std::floor((x + reach - x_min_) * kSubsamples)));
    for (int r = row_first; r <= row_last; ++r) {
      const double wy = brightness * std::exp(-(r - y) * (r - y) * inverse_two_sigma2);
      float* row = &pattern_[static_cast<size_t>(r) * samples_];
      for (int k = k_first; k <= k_last; ++k) {
        const double dx = x_min_ + static_cast<double>(k) / kSubsamples - x;
        row[k] += static_cast<float>(wy * std::exp(-dx * dx * inverse_two_sigma2));
      }
    }
  }

  // The reference image (integer columns) and its window statistics.
  reference_.resize(static_cast<size_t>(height) * columns_);
  for (int v = 0; v < height; ++v) {
    for (int c = 0; c < columns_; ++c) {
      reference_[static_cast<size_t>(v) * columns_ + c] =
          pattern_[static_cast<size_t>(v) * samples_ + static_cast<size_t>(c) * kSubsamples];
    }
  }
  reference_sum_.assign(reference_.size(), 0.0f);
  reference_inverse_norm_.assign(reference_.size(), 0.0f);
  const int n = options.window_px * options.window_px;
  for (int v = radius_; v < height - radius_; ++v) {
    for (int c = radius_; c < columns_ - radius_; ++c) {
      double s1 = 0, s2 = 0;
      for (int j = -radius_; j <= radius_; ++j) {
        const float* row = &reference_[static_cast<size_t>(v + j) * columns_];
        for (int i = -radius_; i <= radius_; ++i) {
          s1 += row[c + i];
          s2 += static_cast<double>(row[c + i]) * row[c + i];
        }
      }
      const double norm2 = s2 - s1 * s1 / n;
      const size_t at = static_cast<size_t>(v) * columns_ + c;
      reference_sum_[at] = static_cast<float>(s1);
      reference_inverse_norm_[at] = norm2 > 0 ? static_cast<float>(1.0 / std::sqrt(norm2)) : 0.0f;
    }
  }
}

float SpeckleMatcher::Reference(int x, int v) const {
  return reference_[static_cast<size_t>(v) * columns_ + (x - x_min_)];
}

float SpeckleMatcher::Pattern(float x, int v) const {
  float position = (x - static_cast<float>(x_min_)) * kSubsamples;
  position = std::clamp(position, 0.0f, static_cast<float>(samples_ - 2));
  const int k = static_cast<int>(position);
  const float t = position - static_cast<float>(k);
  const float* row = &pattern_[static_cast<size_t>(v) * samples_];
  return row[k] + t * (row[k + 1] - row[k]);
}

void SpeckleMatcher::RenderIr(const SpeckleScene& scene, uint32_t key, float* ir) const {
  const auto power = static_cast<float>(options_.projector_power);
  const auto ambient = static_cast<float>(options_.ambient);
  const auto read2 = static_cast<float>(options_.read_noise * options_.read_noise);
  const auto shot = static_cast<float>(options_.shot_gain);
  const auto levels = static_cast<float>((1 << options_.adc_bits) - 1);
  const auto exponent = static_cast<int>(options_.specular_exponent);
  const auto gain = static_cast<float>(options_.specular_gain);
  tbb::parallel_for(tbb::blocked_range<int>(0, height_, 16), [&](const tbb::blocked_range<int>& r) {
    for (int v = r.begin(); v != r.end(); ++v) {
      const size_t row = static_cast<size_t>(v) * width_;
      // Sensor noise: pixels 2k and 2k + 1 take the two normals of pair k.
      float normal[2] = {0.0f, 0.0f};
      for (int u = 0; u < width_; ++u) {
        const size_t p = row + u;
        if ((p & 1) == 0 || u == 0) {
          BoxMuller(CounterHash(key, static_cast<uint32_t>(p >> 1)), &normal[0], &normal[1]);
        }
        float signal = 0.0f;
        const float d = scene.disparity[p];
        if (d != 0.0f) {
          const float z = scene.depth[p];
          const float c = scene.cos_incidence[p];
          const float diffuse = scene.ir_diffuse[p];
          const float specular = scene.ir_specular[p];
          // The pattern reaches the point from the projector unless something is in between
          // (the IR shadow): its column there is u - d (the projector sits at +b). A Lambertian
          // surface returns it; a mirror-like one returns glare without the dots.
          float returned = 0.0f;
          if (!scene.occluded[p]) {
            returned = Pattern(static_cast<float>(u) - d, v) * diffuse * c;
            if (specular > 0.0f) returned += specular * gain * WholePower(c, exponent);
          }
          signal = power * returned / (z * z) + ambient * (diffuse + specular);
        }
        const float value = signal + std::sqrt(read2 + shot * signal) * normal[p & 1];
        ir[p] = std::floor(std::clamp(value, 0.0f, 1.0f) * levels + 0.5f) / levels;
      }
    }
  });
}

void SpeckleMatcher::Match(const SpeckleScene& scene, const float* ir, const SpeckleOutput& output,
                           uint16_t* depth, MissingCause* cause) const {
  // The rendered disparity of every pixel rounded to an integer (-1: nothing hit), the centre
  // of each pixel's search.
  std::vector<int> centre(static_cast<size_t>(width_) * height_);
  for (size_t p = 0; p < centre.size(); ++p) {
    const float d = scene.disparity[p];
    centre[p] = d != 0.0f ? std::min(max_d_ - options_.search_px - 2,
                                      static_cast<int>(std::lround(d)))
                          : -1;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, height_, 8), [&](const tbb::blocked_range<int>& r) {
    for (int v = r.begin(); v != r.end(); ++v) MatchRow(scene, ir, output, v, centre, depth, cause);
  });
}

void SpeckleMatcher::MatchRow(const SpeckleScene& scene, const float* ir,
                              const SpeckleOutput& output, int v, const std::vector<int>& centre,
                              uint16_t* depth, MissingCause* cause) const {
  const int w = width_;
  const int rad = radius_;
  const int n = options_.window_px * options_.window_px;
  const size_t row = static_cast<size_t>(v) * w;
  auto set = [&](int u, uint16_t value, MissingCause why) {
    depth[row + u] = value;
    if (cause != nullptr) cause[row + u] = why;
  };
  if (v < rad || v >= height_ - rad) {
    for (int u = 0; u < w; ++u) set(u, 0, MissingCause::kBorder);
    return;
  }
  // Window sums of the IR image and of its squares.
  std::vector<double> col1(w), col2(w);
  for (int u = 0; u < w; ++u) {
    double s1 = 0, s2 = 0;
    for (int j = -rad; j <= rad; ++j) {
      const double x = ir[row + static_cast<size_t>(j) * w + u];
      s1 += x;
      s2 += x * x;
    }
    col1[u] = s1;
    col2[u] = s2;
  }
  const int search = options_.search_px;
  const auto min_correlation = static_cast<float>(options_.min_correlation);
  const double min_norm2 = options_.min_contrast * options_.min_contrast * n;
  const auto ambiguity = static_cast<float>(options_.ambiguity_ratio);
  std::vector<float> column(kSegment + 2 * rad);
  std::vector<float> cross;
  std::vector<float> score;
  for (int u = 0; u < rad; ++u) set(u, 0, MissingCause::kBorder);
  for (int u = w - rad; u < w; ++u) set(u, 0, MissingCause::kBorder);
  for (int s = rad; s < w - rad; s += kSegment) {
    const int e = std::min(s + kSegment, w - rad);  // pixels [s, e)
    // The integer disparities any window of the segment can need.
    int lo = std::numeric_limits<int>::max(), hi = -1;
    for (int j = -rad; j <= rad; ++j) {
      const int* c = &centre[row + static_cast<size_t>(j) * w];
      for (int u = s - rad; u < e + rad; ++u) {
        if (c[u] < 0) continue;
        lo = std::min(lo, c[u]);
        hi = std::max(hi, c[u]);
      }
    }
    if (hi < 0) {
      for (int u = s; u < e; ++u) set(u, 0, MissingCause::kNothing);
      continue;
    }
    lo = std::max(0, lo - search - 1);
    hi = std::min(max_d_, hi + search + 1);
    const int count = hi - lo + 1;
    const int span = e - s;
    // cross[(D - lo) * kSegment + (u - s)]: the window sum of ir * reference shifted by D.
    cross.assign(static_cast<size_t>(count) * kSegment, 0.0f);
    float* __restrict sums = column.data();
    for (int d = lo; d <= hi; ++d) {
      const int width = span + 2 * rad;
      std::fill_n(sums, width, 0.0f);
      for (int j = -rad; j <= rad; ++j) {
        const float* __restrict a = &ir[row + static_cast<size_t>(j) * w + (s - rad)];
        const float* __restrict b =
            &reference_[static_cast<size_t>(v + j) * columns_ + (s - rad - d - x_min_)];
        for (int k = 0; k < width; ++k) sums[k] += a[k] * b[k];
      }
      float* __restrict out = &cross[static_cast<size_t>(d - lo) * kSegment];
      for (int i = 0; i <= 2 * rad; ++i) {
        for (int k = 0; k < span; ++k) out[k] += sums[k + i];
      }
    }
    for (int u = s; u < e; ++u) {
      const int c0 = centre[row + u];
      if (c0 < 0) {
        set(u, 0, MissingCause::kNothing);
        continue;
      }
      if (scene.occluded[row + u]) {
        set(u, 0, MissingCause::kShadow);
        continue;
      }
      double s1 = 0, s2 = 0;
      for (int i = -rad; i <= rad; ++i) {
        s1 += col1[u + i];
        s2 += col2[u + i];
      }
      const double norm2 = s2 - s1 * s1 / n;
      if (!(norm2 >= min_norm2) || norm2 <= 0) {
        set(u, 0, MissingCause::kLowSignal);
        continue;
      }
      const auto inverse_norm = static_cast<float>(1.0 / std::sqrt(norm2));
      const auto mean = static_cast<float>(s1 / n);
      // Candidates: within search_px of the rendered disparities at the window's centre and
      // the middles of its sides.
      int a = c0, b = c0;
      for (const size_t q : {row + u - rad, row + u + rad, row + u - static_cast<size_t>(rad) * w,
                             row + u + static_cast<size_t>(rad) * w}) {
        if (centre[q] < 0) continue;
        a = std::min(a, centre[q]);
        b = std::max(b, centre[q]);
      }
      a = std::max(lo, a - search);
      b = std::min(hi, b + search);
      score.resize(b - a + 1);
      int best = -1;
      for (int d = a; d <= b; ++d) {
        const size_t at = static_cast<size_t>(v) * columns_ + (u - d - x_min_);
        const float numerator =
            cross[static_cast<size_t>(d - lo) * kSegment + (u - s)] - mean * reference_sum_[at];
        const float zncc = numerator * inverse_norm * reference_inverse_norm_[at];
        score[d - a] = zncc;
        if (best < 0 || zncc > score[best - a]) best = d;
      }
      const float peak = score[best - a];
      if (peak < min_correlation || best == a || best == b) {
        set(u, 0, MissingCause::kNoMatch);
        continue;
      }
      float second = -1.0f;
      for (int d = a; d <= b; ++d) {
        if (std::abs(d - best) >= 2) second = std::max(second, score[d - a]);
      }
      if (second > ambiguity * peak) {
        set(u, 0, MissingCause::kAmbiguous);
        continue;
      }
      // Sub-pixel: the vertex of the parabola through the peak and its neighbours.
      const float left = score[best - 1 - a], right = score[best + 1 - a];
      const float curvature = left - 2.0f * peak + right;
      float offset = curvature < 0.0f ? 0.5f * (left - right) / curvature : 0.0f;
      offset = std::clamp(offset, -0.5f, 0.5f);
      const float disparity = static_cast<float>(best) + offset;
      float z;
      if (output.quantise) {
        const float raw = std::floor(output.raw_offset - output.subpixel_steps * disparity + 0.5f);
        if (raw < 0.0f || raw > 2046.0f) {
          set(u, 0, MissingCause::kRange);
          continue;
        }
        z = output.lattice / (output.raw_offset - raw);
      } else {
        z = output.lattice / (output.subpixel_steps * disparity);
      }
      if (!(z >= output.min_depth && z <= output.max_depth)) {
        set(u, 0, MissingCause::kRange);
        continue;
      }
      set(u, static_cast<uint16_t>(std::min(65535.0f, std::floor(z * output.inverse_scale + 0.5f))),
          MissingCause::kValid);
    }
  }
}

}  // namespace mmh::sim::internal
