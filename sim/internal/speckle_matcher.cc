#include "sim/internal/speckle_matcher.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"
#include "core/simd.h"
#include "sim/internal/avx2_kernels.h"
#include "sim/internal/avx512_kernels.h"
#include "sim/internal/counter_random.h"
#include "sim/internal/depth_kernels.h"

namespace mmh::sim::internal {
namespace {

// A uniform in [0, 1) from 53 bits of a 64-bit hash.
double Uniform(uint64_t h) { return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0); }

// Pixels are matched in tiles of kBand rows by kSegment columns: each tile scores only the
// integer disparities its pixels' searches need, its column products slide down the rows.
constexpr int kSegment = 64;
constexpr int kBand = 8;

// The IR image's constants as floats for the vector loop.
struct IrParams {
  float power = 0, ambient = 0, read2 = 0, shot = 0, levels = 0, gain = 0;
  float x_min = 0;          // the pattern's first column
  float last_position = 0;  // the last pattern sample with a right neighbour
};

// The glare's lobe: out[k] = c[k]^exponent by repeated squaring (whole exponent >= 0; std::pow
// costs about 20 times more), a pass over the row per bit so that the loops vectorise, 0 in the
// IR shadow; x: #n scratch.
MMH_SIMD_CLONES void GlareRow(const float* __restrict c, const uint8_t* __restrict occluded,
                              int exponent, int n, float* __restrict x, float* __restrict out) {
  for (int k = 0; k < n; ++k) {
    out[k] = 1.0f;
    x[k] = c[k];
  }
  for (int e = exponent; e > 0; e >>= 1) {
    if (e & 1) {
      for (int k = 0; k < n; ++k) out[k] *= x[k];
    }
    for (int k = 0; k < n; ++k) x[k] *= x[k];
  }
  for (int k = 0; k < n; ++k) out[k] *= static_cast<float>(occluded[k] == 0);
}

// The dots one row of the IR image sees (docs/sensor.md, "Structured light", step 2): the
// pattern at column u - d (linear between 1/8 px samples of `pattern`), 0 in the IR shadow.
MMH_SIMD_CLONES void DotsRow(const IrParams& p, const float* __restrict pattern,
                             const float* __restrict disparity, const uint8_t* __restrict occluded,
                             int n, float* __restrict dots) {
  const float x_min = p.x_min, last_position = p.last_position;
  for (int u = 0; u < n; ++u) {
    float position = (static_cast<float>(u) - disparity[u] - x_min) * 8.0f;
    position = position > 0.0f ? position : 0.0f;
    position = position < last_position ? position : last_position;
    const int k = static_cast<int>(position);
    const float t = position - static_cast<float>(k);
    // The pattern reaches the point from the projector unless something is in between (the IR
    // shadow). (Selections as products with 0 or 1 so that the loops vectorise.)
    dots[u] =
        (pattern[k] + t * (pattern[k + 1] - pattern[k])) * static_cast<float>(occluded[u] == 0);
  }
}

// One row of the IR image in ADC counts from its dots (DotsRow): Lambertian return, glare
// (cos^n precomputed), 1 / z^2 fall-off, ambient light, sensor noise (normal: standard normals),
// clip, quantisation.
MMH_SIMD_CLONES void IrRow(const IrParams& p, const float* __restrict depth,
                           const float* __restrict disparity, const float* __restrict cos_incidence,
                           const float* __restrict diffuse, const float* __restrict specular,
                           const float* __restrict glare, const float* __restrict normal,
                           const float* __restrict dots, int n, uint16_t* __restrict ir) {
  const float power = p.power, ambient = p.ambient, read2 = p.read2, shot = p.shot,
              levels = p.levels, gain = p.gain;
  for (int u = 0; u < n; ++u) {
    const float d = disparity[u];
    const bool hit = d != 0.0f;
    // A Lambertian surface returns the pattern; a mirror-like one returns glare without the
    // dots (none in the IR shadow: glare[u] is 0 there).
    const float returned = dots[u] * diffuse[u] * cos_incidence[u] + specular[u] * gain * glare[u];
    // Pixels that see nothing get a harmless depth so that the arithmetic stays finite.
    const float z = hit ? depth[u] : 1.0f;
    float signal = power * returned / (z * z) + ambient * (diffuse[u] + specular[u]);
    signal = hit ? signal : 0.0f;
    const float value = signal + std::sqrt(read2 + shot * signal) * normal[u];
    float clipped = value > 0.0f ? value : 0.0f;
    clipped = clipped < 1.0f ? clipped : 1.0f;
    ir[u] = static_cast<uint16_t>(static_cast<int>(std::floor(clipped * levels + 0.5f)));
  }
}

// Window sums down the columns: sum[k] = sum_j a[j stride + k], square[k] likewise of a^2, over
// `rows` rows (exact: ADC counts, MatchableWindow).
MMH_SIMD_CLONES void ColumnSums(const int32_t* __restrict a, size_t stride, int rows, int n,
                                int32_t* __restrict sum, int32_t* __restrict square) {
  for (int k = 0; k < n; ++k) {
    sum[k] = 0;
    square[k] = 0;
  }
  for (int j = 0; j < rows; ++j) {
    const int32_t* __restrict row = a + static_cast<size_t>(j) * stride;
    for (int k = 0; k < n; ++k) {
      const int32_t x = row[k];
      sum[k] += x;
      square[k] += x * x;
    }
  }
}

// Column products are computed in blocks of this many (the vector loops then need no
// remainder; the IR rows and the reference are padded).
constexpr int kBlock = 16;
int RoundUp(int n) { return (n + kBlock - 1) / kBlock * kBlock; }

// out[k] = sum_j a[j a_stride + k] b[j b_stride + k] over `rows` rows (exact), n a multiple of
// kBlock.
MMH_SIMD_CLONES void ColumnProducts(const int32_t* __restrict a, size_t a_stride,
                                    const int32_t* __restrict b, size_t b_stride, int rows, int n,
                                    int32_t* __restrict out) {
  for (int k = 0; k < n; ++k) out[k] = 0;
  for (int j = 0; j < rows; ++j) {
    const int32_t* __restrict aj = a + static_cast<size_t>(j) * a_stride;
    const int32_t* __restrict bj = b + static_cast<size_t>(j) * b_stride;
    for (int base = 0; base < n; base += kBlock) {
      for (int k = base; k < base + kBlock; ++k) out[k] += aj[k] * bj[k];
    }
  }
}

// Moves column products one row down: sums[k] += a_in[k] b_in[k] - a_out[k] b_out[k] (exact), n a
// multiple of kBlock.
MMH_SIMD_CLONES void SlideProducts(const int32_t* __restrict a_in, const int32_t* __restrict b_in,
                                   const int32_t* __restrict a_out, const int32_t* __restrict b_out,
                                   int n, int32_t* __restrict sums) {
  for (int base = 0; base < n; base += kBlock) {
    for (int k = base; k < base + kBlock; ++k) {
      sums[k] += a_in[k] * b_in[k] - a_out[k] * b_out[k];
    }
  }
}

// The IR window's rows as 32-bit integers, each padded with kBlock zeros.
MMH_SIMD_CLONES void WidenRows(const uint16_t* __restrict ir, int width, int rows,
                               int32_t* __restrict out) {
  const int stride = width + kBlock;
  for (int j = 0; j < rows; ++j) {
    for (int k = 0; k < width; ++k) out[j * stride + k] = ir[j * width + k];
    for (int k = width; k < stride; ++k) out[j * stride + k] = 0;
  }
}

// BoxSums of the default 9-pixel window: each output summed directly (9 loads from L1, no
// intermediate passes through memory; integer sums, so the same values).
MMH_SIMD_CLONES void BoxSums9(const int32_t* __restrict in, int n, int32_t* __restrict out) {
  for (int k = 0; k < n; ++k) {
    out[k] = in[k] + in[k + 1] + in[k + 2] + in[k + 3] + in[k + 4] + in[k + 5] + in[k + 6] +
             in[k + 7] + in[k + 8];
  }
}

// out[k] = sum_{i < window} in[k + i] (exact), by doubling: sums of 1, 2, 4, ... consecutive
// values, those of window's binary digits added up (5 passes for 9 instead of 9); a and b:
// scratch of n + window.
MMH_SIMD_CLONES void BoxSums(const int32_t* __restrict in, int window, int n, int32_t* __restrict a,
                             int32_t* __restrict b, int32_t* __restrict out) {
  if (window == 9) {
    BoxSums9(in, n, out);
    return;
  }
  const int total = n + window - 1;
  const int32_t* sums = in;  // sums of `width` consecutive values, valid for k < total - width + 1
  int32_t* next = a;
  int offset = 0;
  for (int width = 1;; width *= 2) {
    if (window & width) {
      if (offset == 0) {
        for (int k = 0; k < n; ++k) out[k] = sums[k];
      } else {
        for (int k = 0; k < n; ++k) out[k] += sums[k + offset];
      }
      offset += width;
    }
    if (2 * width > window) break;
    const int valid = total - 2 * width + 1;
    for (int k = 0; k < valid; ++k) next[k] = sums[k] + sums[k + width];
    sums = next;
    next = next == a ? b : a;
  }
}

// Zero-mean normalised cross-correlation of windows of `count` pixels from their sums at
// disparity d: (count cross - sum_a sum_b) / sqrt((count sq_a - sum_a^2) (count sq_b - sum_b^2)),
// with the inverse square roots given (the numerator is an integer below 2^53: exact in double);
// then each pixel's best score over the disparities of its search [first, last] and the scores
// beside it (for the parabola): called for each d in increasing order (ties keep the smaller d;
// previous: the scores at d - 1).
MMH_SIMD_CLONES void ScoreAndTakeBest(
    const int32_t* __restrict cross, const int32_t* __restrict sum_a,
    const double* __restrict inverse_a, const int32_t* __restrict sum_b,
    const double* __restrict inverse_b, double count, int d, const int* __restrict first,
    const int* __restrict last, int n, const double* __restrict previous, double* __restrict score,
    double* __restrict best, int* __restrict best_d, double* __restrict left,
    double* __restrict right) {
  for (int k = 0; k < n; ++k) {
    const double numerator = count * static_cast<double>(cross[k]) -
                             static_cast<double>(sum_a[k]) * static_cast<double>(sum_b[k]);
    const double x = numerator * inverse_a[k] * inverse_b[k];
    score[k] = x;
    right[k] = d == best_d[k] + 1 ? x : right[k];
    const bool better = (d >= first[k]) & (d <= last[k]) & (x > best[k]);
    best[k] = better ? x : best[k];
    best_d[k] = better ? d : best_d[k];
    left[k] = better ? previous[k] : left[k];
  }
}

// The best score at least two pixels from the peak (the ambiguity test).
MMH_SIMD_CLONES void TakeSecond(const double* __restrict score, int d, const int* __restrict first,
                                const int* __restrict last, const int* __restrict best_d, int n,
                                double* __restrict second) {
  for (int k = 0; k < n; ++k) {
    const int distance = d - best_d[k];
    const bool take = (d >= first[k]) & (d <= last[k]) & ((distance >= 2) | (distance <= -2)) &
                      (score[k] > second[k]);
    second[k] = take ? score[k] : second[k];
  }
}

// 1 / sqrt(n square - sum^2) of the IR windows, 0 where that is below min_norm2 (low signal).
MMH_SIMD_CLONES void InverseNorms(const int32_t* __restrict sum, const int32_t* __restrict square,
                                  double count, double min_norm2, int n,
                                  double* __restrict inverse_norm) {
  for (int k = 0; k < n; ++k) {
    const double norm2 = count * static_cast<double>(square[k]) -
                         static_cast<double>(sum[k]) * static_cast<double>(sum[k]);
    const bool low = !(norm2 >= min_norm2) | (norm2 <= 0.0);
    inverse_norm[k] = low ? 0.0 : 1.0 / std::sqrt(norm2);
  }
}

// The integer disparity at which each pixel's search is centred: the rendered disparity rounded,
// at most `largest` (-1: nothing hit; in `low` a large number instead of -1).
MMH_SIMD_CLONES void Centres(const float* __restrict disparity, int largest, size_t n,
                             int* __restrict centre, int* __restrict low) {
  for (size_t p = 0; p < n; ++p) {
    const int rounded = static_cast<int>(std::floor(disparity[p] + 0.5f));
    const int c = disparity[p] != 0.0f ? std::min(largest, rounded) : -1;
    centre[p] = c;
    low[p] = c < 0 ? std::numeric_limits<int>::max() / 2 : c;
  }
}

// Why a pixel is not searched before its window is looked at: nothing hit, or hidden from a
// source whose bit is in `blocking` (SpeckleScene::occluded).
MMH_SIMD_CLONES void GeometryBlocked(const int* __restrict centre,
                                     const uint8_t* __restrict occluded, uint8_t blocking, size_t n,
                                     int* __restrict blocked) {
  for (size_t p = 0; p < n; ++p) {
    const int shadow = (occluded[p] & blocking) != 0 ? static_cast<int>(MissingCause::kShadow) : 0;
    blocked[p] = centre[p] < 0 ? static_cast<int>(MissingCause::kNothing) : shadow;
  }
}

// Why a pixel is not searched (0: it is): nothing hit, IR shadow, low signal.
MMH_SIMD_CLONES void WindowBlocked(const int* __restrict blocked,
                                   const double* __restrict inverse_norm, int n,
                                   int* __restrict pre) {
  for (int k = 0; k < n; ++k) {
    const int low = inverse_norm[k] == 0.0 ? static_cast<int>(MissingCause::kLowSignal) : 0;
    pre[k] = blocked[k] != 0 ? blocked[k] : low;
  }
}

// Each pixel's search [first, last]: within `search` of the smallest and largest search centre
// at the window's centre and the middles of its sides (low: centres with "nothing hit" as a
// large number; high: as -1), or none (first > last) where pre is not 0.
MMH_SIMD_CLONES void SearchRanges(const int* __restrict low, const int* __restrict low_up,
                                  const int* __restrict low_down, const int* __restrict high,
                                  const int* __restrict high_up, const int* __restrict high_down,
                                  const int* __restrict pre, int side, int search, int max_d, int n,
                                  int* __restrict first, int* __restrict last) {
  for (int k = 0; k < n; ++k) {
    const int a = std::min(
        std::min(std::min(low[k], low[k - side]), std::min(low[k + side], low_up[k])), low_down[k]);
    const int b =
        std::max(std::max(std::max(high[k], high[k - side]), std::max(high[k + side], high_up[k])),
                 high_down[k]);
    first[k] = pre[k] == 0 ? std::max(0, a - search) : std::numeric_limits<int>::max();
    last[k] = pre[k] == 0 ? std::min(max_d, b + search) : -1;
  }
}

// The verdict on each pixel of a segment (docs/sensor.md, "Structured light", step 4) as a
// MissingCause, and its disparity: the vertex of the parabola through the peak and its
// neighbours.
MMH_SIMD_CLONES void Decide(const double* __restrict best, const int* __restrict best_d,
                            const double* __restrict second, const double* __restrict left,
                            const double* __restrict right, const int* __restrict first,
                            const int* __restrict last, const int* __restrict pre,
                            double min_correlation, double ambiguity, int n, int* __restrict code,
                            float* __restrict disparity) {
  for (int k = 0; k < n; ++k) {
    const double peak = best[k];
    const int d = best_d[k];
    const bool no_match = (peak < min_correlation) | (d == first[k]) | (d == last[k]);
    const bool ambiguous = second[k] > ambiguity * peak;
    // Three-point Gaussian fit (the vertex of the parabola through the logarithms): the
    // correlation peak of Gaussian speckle dots is Gaussian, and a parabola through the scores
    // themselves pulls the disparity towards whole pixels (pixel locking, which real Kinect
    // frames do not show: docs/sensor.md). A parabola where a score is not positive.
    const bool positive = (left[k] > 0.0) & (peak > 0.0) & (right[k] > 0.0);
    const double l = positive ? static_cast<double>(LnUnit(static_cast<float>(left[k]))) : left[k];
    const double m = positive ? static_cast<double>(LnUnit(static_cast<float>(peak))) : peak;
    const double r =
        positive ? static_cast<double>(LnUnit(static_cast<float>(right[k]))) : right[k];
    const double curvature = l - 2.0 * m + r;
    double offset = curvature < 0.0 ? 0.5 * (l - r) / curvature : 0.0;
    offset = offset > -0.5 ? offset : -0.5;
    offset = offset < 0.5 ? offset : 0.5;
    disparity[k] = static_cast<float>(d + offset);
    int c = ambiguous ? static_cast<int>(MissingCause::kAmbiguous) : 0;
    c = no_match ? static_cast<int>(MissingCause::kNoMatch) : c;
    code[k] = pre[k] != 0 ? pre[k] : c;
  }
}

// One window of the IR image against one of the lattice reference: sums[0] = sum a b, sums[1] =
// sum b, sums[2] = sum b^2 over `window` rows of `window` values (exact 32-bit integers).
MMH_SIMD_CLONES void WindowProducts(const int32_t* __restrict a, size_t a_stride,
                                    const int32_t* __restrict b, size_t b_stride, int window,
                                    int32_t* __restrict sums) {
  int32_t cross = 0, sum = 0, square = 0;
  for (int j = 0; j < window; ++j) {
    const int32_t* x = a + j * a_stride;
    const int32_t* y = b + j * b_stride;
    for (int i = 0; i < window; ++i) {
      cross += x[i] * y[i];
      sum += y[i];
      square += y[i] * y[i];
    }
  }
  sums[0] = cross;
  sums[1] = sum;
  sums[2] = square;
}

// Depth units of matched pixels on the raw lattice (raw = round(raw_offset - 8 d), units from
// the table, 0 outside [0, 2046] or the depth range: kRange); other pixels keep their code.
MMH_SIMD_CLONES void LatticeDepth(const SpeckleOutput& output, const int32_t* __restrict table,
                                  const int* __restrict code, const float* __restrict disparity,
                                  int n, int32_t* __restrict units, int32_t* __restrict why) {
  const float raw_offset = output.raw_offset, steps = output.subpixel_steps;
  for (int k = 0; k < n; ++k) {
    // Index 2047 (table entry 0): off the lattice (raw < 0 or > 2046) or not matched; written
    // with min, max and bit masks, which GCC vectorises.
    float raw = std::floor(raw_offset - steps * disparity[k] + 0.5f);
    raw = std::max(-1.0f, std::min(raw, 2047.0f));
    const int index = (static_cast<int>(raw) | (code[k] != 0 ? 2047 : 0)) & 2047;
    units[k] = table[index];
  }
  for (int k = 0; k < n; ++k) {
    why[k] = code[k] != 0 ? code[k] : units[k] != 0 ? 0 : static_cast<int>(MissingCause::kRange);
  }
}

}  // namespace

// Per task: a band's searches and window statistics (kBand rows), a segment's running column
// products and scores.
struct SpeckleMatcher::BandScratch {
  explicit BandScratch(int width)
      : first(kBand * width),
        last(kBand * width),
        pre(kBand * width),
        sum(kBand * width),
        inverse_norm(kBand * width),
        column_sum(width),
        column_square(width),
        square(width),
        box_a(width + kBlock + 32),
        box_b(width + kBlock + 32),
        cross(kSegment),
        code(kSegment),
        disparity(kSegment),
        best(kSegment),
        second(kSegment),
        left(kSegment),
        right(kSegment),
        none(kSegment, 0.0),
        best_d(kSegment) {}
  // Per row of the band (r width + u):
  std::vector<int> first, last;      // the search [first, last] (first > last: none)
  std::vector<int> pre;              // why a pixel is not searched (MissingCause; 0: it is)
  std::vector<int32_t> sum;          // the IR window's sum
  std::vector<double> inverse_norm;  // 1 / sqrt(n sum of squares - sum^2); 0: low signal
  // Per row:
  std::vector<int32_t> column_sum, column_square, square;
  std::vector<int32_t> box_a, box_b;  // BoxSums' scratch
  // Per segment:
  std::vector<int32_t> products;  // window column products, (d - lo) stride + k
  std::vector<int32_t> cross;    // window sums of the products (AVX2: (d - row lo) kSegment + k)
  std::vector<double> scores;    // (d - lo) kSegment + k
  std::vector<int> code;         // the verdict (MissingCause) per pixel
  std::vector<float> disparity;  // the matched disparity per pixel
  std::vector<double> best, second, left, right;
  std::vector<double> none;  // the "scores at d - 1" of the first disparity (never used)
  std::vector<int> best_d;
};

SpeckleMatcher::SpeckleMatcher(const StructuredLightOptions& options, int width, int height,
                               double max_disparity)
    : options_(options),
      width_(width),
      height_(height),
      radius_(options.window_px / 2),
      levels_((1 << options.adc_bits) - 1) {
  max_d_ = static_cast<int>(std::ceil(max_disparity)) + options.search_px + 2;
  x_min_ = -max_d_ - radius_ - 2;
  const int x_max = width + radius_ + 2 + kBlock;  // kBlock: ColumnProducts' padding
  columns_ = x_max - x_min_ + 1;
  samples_ = columns_ * kSubsamples + 1;
  pattern_.assign(static_cast<size_t>(height) * samples_, 0.0f);

  // Dots at random positions over the pattern's extent (plus a margin for their tails), each a
  // Gaussian of dot_sigma_px with a brightness uniform in [0.5, 1] (times `scale`); added in dot
  // order, the bright ones first, so the pattern is the same on every machine and thread count
  // (and without faint dots the same as before they existed).
  const double sigma = options.dot_sigma_px;
  const double reach = 3.0 * sigma;
  const double x0 = x_min_ - reach, x1 = x_max + reach;
  const double y0 = -reach, y1 = height + reach;
  const double inverse_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
  auto add_dots = [&](double density, double scale, uint64_t stream) {
    const auto dots = static_cast<uint64_t>(std::llround(density * (x1 - x0) * (y1 - y0)));
    for (uint64_t i = 0; i < dots; ++i) {
      const uint64_t key =
          Mix64(options.pattern_seed ^ Mix64(3 * i + 0x9E3779B97F4A7C15ULL) ^ stream);
      const double x = x0 + (x1 - x0) * Uniform(key);
      const double y = y0 + (y1 - y0) * Uniform(Mix64(key + 1));
      const double brightness = scale * (0.5 + 0.5 * Uniform(Mix64(key + 2)));
      const int row_first = std::max(0, static_cast<int>(std::ceil(y - reach)));
      const int row_last = std::min(height - 1, static_cast<int>(std::floor(y + reach)));
      const int k_first =
          std::max(0, static_cast<int>(std::ceil((x - reach - x_min_) * kSubsamples)));
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
  };
  add_dots(options.dot_density, 1.0, 0);
  if (options.faint_dot_density > 0) {
    add_dots(options.faint_dot_density, options.faint_dot_brightness, 0xFA1D07F00D5EEDULL);
  }

  // The reference image: the pattern at integer columns, captured by the same camera (ADC
  // counts; scaled so that the brightest sample is full scale: ZNCC does not see the scale).
  float peak = 0.0f;
  for (const float x : pattern_) peak = std::max(peak, x);
  const double scale = peak > 0.0f ? levels_ / static_cast<double>(peak) : 0.0;
  reference_scale_ = scale;
  reference_.resize(static_cast<size_t>(height) * columns_);
  for (int v = 0; v < height; ++v) {
    for (int c = 0; c < columns_; ++c) {
      reference_[static_cast<size_t>(v) * columns_ + c] = static_cast<int32_t>(std::lround(
          scale *
          pattern_[static_cast<size_t>(v) * samples_ + static_cast<size_t>(c) * kSubsamples]));
    }
  }
  // Its window statistics (exact integer sums).
  reference_sum_.assign(reference_.size(), 0);
  reference_inverse_norm_.assign(reference_.size(), 0.0);
  const int window = options.window_px;
  const int64_t n = static_cast<int64_t>(window) * window;
  std::vector<int64_t> column_sum(columns_), column_square(columns_);
  for (int v = radius_; v < height - radius_; ++v) {
    std::fill(column_sum.begin(), column_sum.end(), 0);
    std::fill(column_square.begin(), column_square.end(), 0);
    for (int j = -radius_; j <= radius_; ++j) {
      const int32_t* row = &reference_[static_cast<size_t>(v + j) * columns_];
      for (int c = 0; c < columns_; ++c) {
        column_sum[c] += row[c];
        column_square[c] += static_cast<int64_t>(row[c]) * row[c];
      }
    }
    for (int c = radius_; c < columns_ - radius_; ++c) {
      int64_t s1 = 0, s2 = 0;
      for (int i = -radius_; i <= radius_; ++i) {
        s1 += column_sum[c + i];
        s2 += column_square[c + i];
      }
      const int64_t norm2 = n * s2 - s1 * s1;
      const size_t at = static_cast<size_t>(v) * columns_ + c;
      reference_sum_[at] = static_cast<int32_t>(s1);
      reference_inverse_norm_[at] = norm2 > 0 ? 1.0 / std::sqrt(static_cast<double>(norm2)) : 0.0;
    }
  }
}

SpeckleMatcher::~SpeckleMatcher() = default;

int SpeckleMatcher::Reference(int x, int v) const {
  return reference_[static_cast<size_t>(v) * columns_ + (x - x_min_)];
}

float SpeckleMatcher::ScatteredPattern(float x, int v, float sigma_px,
                                       std::vector<float>& weights) const {
  // A Gaussian of sigma_px over rows (whole rows: the pattern is sampled per row) and over
  // columns every quarter pixel, to three sigma, normalised.
  constexpr float kStep = 0.25f;
  const int rows = static_cast<int>(std::ceil(3.0f * sigma_px));
  const int columns = static_cast<int>(std::ceil(3.0f * sigma_px / kStep));
  const float inverse = 1.0f / (2.0f * sigma_px * sigma_px);
  weights.resize(2 * static_cast<size_t>(columns) + 1);
  for (int i = -columns; i <= columns; ++i) {
    const float dx = i * kStep;
    weights[i + columns] = std::exp(-dx * dx * inverse);
  }
  double sum = 0, total = 0;
  for (int j = -rows; j <= rows; ++j) {
    const float row_weight = std::exp(-static_cast<float>(j * j) * inverse);
    const int r = std::clamp(v + j, 0, height_ - 1);
    for (int i = -columns; i <= columns; ++i) {
      const float weight = row_weight * weights[i + columns];
      sum += static_cast<double>(weight) * Pattern(x + i * kStep, r);
      total += weight;
    }
  }
  return static_cast<float>(sum / total);
}

void SpeckleMatcher::ScatterDots(const SpeckleScene& scene, int v, float* dots,
                                 std::vector<float>& weights) const {
  // The dots around each translucent pixel's entry point, blurred by the spread under its surface
  // (subsurface_m f / z pixels at depth z; below 0.05 px it is no blur).
  const size_t row = static_cast<size_t>(v) * width_;
  for (int u = 0; u < width_; ++u) {
    const size_t q = row + u;
    if (!(scene.subsurface_m[q] > 0) || scene.disparity[q] == 0.0f || scene.occluded[q] != 0) {
      continue;
    }
    const float sigma = scene.subsurface_m[q] * scene.focal_px / scene.depth[q];
    if (sigma < 0.05f) continue;
    dots[u] = ScatteredPattern(static_cast<float>(u) - scene.disparity[q], v, sigma, weights);
  }
}

float SpeckleMatcher::Pattern(float x, int v) const {
  float position = (x - static_cast<float>(x_min_)) * kSubsamples;
  position = std::clamp(position, 0.0f, static_cast<float>(samples_ - 2));
  const int k = static_cast<int>(position);
  const float t = position - static_cast<float>(k);
  const float* row = &pattern_[static_cast<size_t>(v) * samples_];
  return row[k] + t * (row[k + 1] - row[k]);
}

int SpeckleMatcher::SearchCentre(float disparity) const {
  int centre, low;
  Centres(&disparity, max_d_ - options_.search_px - 2, 1, &centre, &low);
  return centre;
}

void SpeckleMatcher::RenderIr(const SpeckleScene& scene, uint32_t key, uint16_t* ir) const {
  IrParams p;
  p.power = static_cast<float>(options_.projector_power);
  p.ambient = static_cast<float>(options_.ambient);
  p.read2 = static_cast<float>(options_.read_noise * options_.read_noise);
  p.shot = static_cast<float>(options_.shot_gain);
  p.levels = static_cast<float>(levels_);
  p.gain = static_cast<float>(options_.specular_gain);
  p.x_min = static_cast<float>(x_min_);
  p.last_position = static_cast<float>(samples_ - 2);
  const auto exponent = static_cast<int>(options_.specular_exponent);
  // Sensor noise: pixels 2k and 2k + 1 take the two normals of the Box-Muller pair k (the depth
  // model's generator, keyed by `key`).
  DepthParams noise;
  noise.key_c = key;
  tbb::parallel_for(tbb::blocked_range<int>(0, height_, 16), [&](const tbb::blocked_range<int>& r) {
    const int w = width_;
    std::vector<float> normal(w), glare(w), scratch(w), dots(w), blur_weights;
    std::vector<uint32_t> unused(w);
    for (int v = r.begin(); v != r.end(); ++v) {
      const size_t row = static_cast<size_t>(v) * w;
      DepthNoise(noise, static_cast<uint32_t>(row), w, unused.data(), normal.data());
      GlareRow(scene.cos_incidence + row, scene.occluded + row, exponent, w, scratch.data(),
               glare.data());
      DotsRow(p, &pattern_[static_cast<size_t>(v) * samples_], scene.disparity + row,
              scene.occluded + row, w, dots.data());
      if (scene.subsurface_m != nullptr) ScatterDots(scene, v, dots.data(), blur_weights);
      IrRow(p, scene.depth + row, scene.disparity + row, scene.cos_incidence + row,
            scene.ir_diffuse + row, scene.ir_specular + row, glare.data(), normal.data(),
            dots.data(), w, ir + row);
    }
  });
}

void SpeckleMatcher::Match(const SpeckleScene& scene, const uint16_t* ir,
                           const SpeckleOutput& output, uint16_t* depth, MissingCause* cause) {
  const size_t pixels = static_cast<size_t>(width_) * height_;
  centre_.resize(pixels);
  centre_low_.resize(pixels);
  blocked_.resize(pixels);
  Centres(scene.disparity, max_d_ - options_.search_px - 2, pixels, centre_.data(),
          centre_low_.data());
  // A window centred in the projector's shadow is matched like any other when
  // match_in_shadow: its lit part may still correlate, as on the device, which does not know
  // where the shadow is. The IR camera's occlusion stays blocked (the IR image here is the
  // delivered camera's, not the IR camera's own view).
  const uint8_t blocking = options_.match_in_shadow
                               ? kIrCameraBit
                               : static_cast<uint8_t>(kProjectorShadowBit | kIrCameraBit);
  GeometryBlocked(centre_.data(), scene.occluded, blocking, pixels, blocked_.data());
  // Depth units of each raw value on the lattice (0: outside [min_depth, max_depth]).
  units_by_raw_.assign(2048, 0);  // 2048: raw 2047 means "off the lattice"
  for (int raw = 0; raw <= 2046; ++raw) {
    const float z = output.lattice / (output.raw_offset - static_cast<float>(raw));
    units_by_raw_[raw] =
        z >= output.min_depth && z <= output.max_depth
            ? static_cast<int32_t>(std::min(65535.0f, std::floor(z * output.inverse_scale + 0.5f)))
            : 0;
  }
  if (options_.lattice_search && output.raw_offset != lattice_offset_) {
    if (output.subpixel_steps != kSubsamples) {
      ThrowBadValue("sensor.structured_light.lattice_search", "true",
                    "false with subpixel_steps " + std::to_string(output.subpixel_steps) +
                        " (the pattern is sampled every 1/" + std::to_string(kSubsamples) +
                        " px)");
    }
    // Raw value r shifts the reference by raw_offset - r samples: position (u - x_min) 8 -
    // raw_offset + r = k + phase with k = (u - x_min) 8 + r + floor(-raw_offset).
    lattice_floor_ = static_cast<int>(std::floor(-output.raw_offset));
    const double phase = -static_cast<double>(output.raw_offset) - lattice_floor_;
    const size_t plane = static_cast<size_t>(height_) * columns_;
    lattice_reference_.assign(kSubsamples * plane, 0);
    for (int q = 0; q < kSubsamples; ++q) {
      for (int v = 0; v < height_; ++v) {
        const float* row = &pattern_[static_cast<size_t>(v) * samples_];
        int32_t* out = &lattice_reference_[q * plane + static_cast<size_t>(v) * columns_];
        for (int c = 0; c < columns_; ++c) {
          const int k = c * kSubsamples + q;
          if (k + 1 >= samples_) continue;
          out[c] = static_cast<int32_t>(
              std::lround(reference_scale_ * (row[k] + phase * (row[k + 1] - row[k]))));
        }
      }
    }
    lattice_offset_ = output.raw_offset;
  }
  // The IR image as padded 32-bit rows.
  const int stride = width_ + kBlock;
  wide_ir_.resize(static_cast<size_t>(height_) * stride);
  WidenRows(ir, width_, height_, wide_ir_.data());
  // Rows whose window leaves the image.
  const int rad = radius_;
  for (int v = 0; v < height_; ++v) {
    if (v >= rad && v < height_ - rad) continue;
    std::fill_n(depth + static_cast<size_t>(v) * width_, width_, uint16_t{0});
    if (cause != nullptr) {
      std::fill_n(cause + static_cast<size_t>(v) * width_, width_, MissingCause::kBorder);
    }
  }
  // slanted_windows requires parabola_subpixel (StructuredLightOptions::Validate).
  const bool slanted = options_.slanted_windows != SlantedWindows::kOff;
  if (slanted) {
    if (options_.slanted_windows == SlantedWindows::kFirstOrder) PrepareCentroids();
    frame_code_.assign(pixels, static_cast<int>(MissingCause::kBorder));
    frame_disparity_.assign(pixels, 0.0f);
  }
  const int bands = (height_ - 2 * rad + kBand - 1) / kBand;
  // Every band overwrites what it reads of its scratch: which worker's scratch a band gets does
  // not change its bytes.
  scratch_.resize(std::max<size_t>(scratch_.size(), tbb::this_task_arena::max_concurrency()));
  tbb::parallel_for(tbb::blocked_range<int>(0, bands), [&](const tbb::blocked_range<int>& r) {
    std::unique_ptr<BandScratch>& slot = scratch_[tbb::this_task_arena::current_thread_index()];
    if (!slot) slot = std::make_unique<BandScratch>(width_);
    BandScratch& scratch = *slot;
    for (int b = r.begin(); b != r.end(); ++b) {
      const int v0 = rad + b * kBand;
      MatchBand(scene, output, v0, std::min(v0 + kBand, height_ - rad), scratch, depth, cause,
                slanted ? frame_code_.data() : nullptr,
                slanted ? frame_disparity_.data() : nullptr);
    }
  });
  if (!slanted) return;
  // The second pass needs the first match's disparities under every window: after all bands.
  // Its sums are exact integers, so where a task starts does not change them.
  tbb::parallel_for(tbb::blocked_range<int>(rad, height_ - rad, kBand),
                    [&](const tbb::blocked_range<int>& r) {
                      RefineSlantedRows(output, r.begin(), r.end(), depth, cause);
                    });
}

void SpeckleMatcher::PrepareRow(int v, int r, BandScratch& s) const {
  const int w = width_;
  const int rad = radius_;
  const int window = options_.window_px;
  const int n = window * window;
  const size_t row = static_cast<size_t>(v) * w;
  const size_t at = static_cast<size_t>(r) * w;
  // The IR windows' sums and contrast: low signal where the sum of squared deviations (in full
  // scale units) is below min_contrast^2 n, i.e. n sq - sum^2 below min_contrast^2 n^2 levels^2.
  const int stride = w + kBlock;
  ColumnSums(&wide_ir_[static_cast<size_t>(v - rad) * stride], stride, window, w,
             s.column_sum.data(), s.column_square.data());
  BoxSums(s.column_sum.data(), window, w - 2 * rad, s.box_a.data(), s.box_b.data(),
          &s.sum[at + rad]);
  BoxSums(s.column_square.data(), window, w - 2 * rad, s.box_a.data(), s.box_b.data(),
          s.square.data() + rad);
  const double min_norm2 = options_.min_contrast * options_.min_contrast * n * n *
                           static_cast<double>(levels_) * levels_;
  InverseNorms(&s.sum[at + rad], s.square.data() + rad, n, min_norm2, w - 2 * rad,
               &s.inverse_norm[at + rad]);
  // Each pixel's search: within search_px of the rendered disparities at the window's centre
  // and the middles of its sides (a window across a depth edge scores both surfaces).
  WindowBlocked(&blocked_[row + rad], &s.inverse_norm[at + rad], w - 2 * rad, &s.pre[at + rad]);
  // (Without edge_candidates the "sides" are the centre itself.)
  const int side = options_.edge_candidates ? rad : 0;
  const size_t up = row - static_cast<size_t>(side) * w, down = row + static_cast<size_t>(side) * w;
  SearchRanges(&centre_low_[row + rad], &centre_low_[up + rad], &centre_low_[down + rad],
               &centre_[row + rad], &centre_[up + rad], &centre_[down + rad], &s.pre[at + rad],
               side, options_.search_px, max_d_, w - 2 * rad, &s.first[at + rad],
               &s.last[at + rad]);
}

void SpeckleMatcher::MatchBand(const SpeckleScene& scene, const SpeckleOutput& output, int v0,
                               int v1, BandScratch& s, uint16_t* depth, MissingCause* cause,
                               int* first_code, float* first_disparity) const {
  const int w = width_;
  const int rad = radius_;
  const int window = options_.window_px;
  const int n = window * window;
  const int stride = w + kBlock;
  for (int v = v0; v < v1; ++v) {
    const size_t row = static_cast<size_t>(v) * w;
    std::fill_n(depth + row, rad, uint16_t{0});
    std::fill_n(depth + row + (w - rad), rad, uint16_t{0});
    if (cause != nullptr) {
      std::fill_n(cause + row, rad, MissingCause::kBorder);
      std::fill_n(cause + row + (w - rad), rad, MissingCause::kBorder);
    }
    PrepareRow(v, v - v0, s);
  }
  const auto min_correlation = options_.min_correlation;
  const auto ambiguity = options_.ambiguity_ratio;
  for (int start = rad; start < w - rad; start += kSegment) {
    const int end = std::min(start + kSegment, w - rad);  // pixels [start, end)
    const int span = end - start;
    const int length = RoundUp(span + 2 * rad);  // column products per disparity
    // Every disparity some pixel of the tile needs.
    int lo = std::numeric_limits<int>::max(), hi = -1;
    for (int r = 0; r < v1 - v0; ++r) {
      for (int u = start; u < end; ++u) {
        lo = std::min(lo, s.first[static_cast<size_t>(r) * w + u]);
        hi = std::max(hi, s.last[static_cast<size_t>(r) * w + u]);
      }
    }
    const int count = hi >= lo ? hi - lo + 1 : 0;
    s.products.resize(static_cast<size_t>(count) * length);
    s.scores.resize(static_cast<size_t>(count) * kSegment);
    s.cross.resize(static_cast<size_t>(count) * kSegment);
    for (int v = v0; v < v1; ++v) {
      const size_t at = static_cast<size_t>(v - v0) * w;
      // The window's column products at every disparity: summed down the window for the
      // tile's first row, then slid down one row at a time (exact integers).
      for (int d = lo; d <= hi; ++d) {
        const size_t reference_at = static_cast<size_t>(start - rad - d - x_min_);
        int32_t* products = &s.products[static_cast<size_t>(d - lo) * length];
        if (v == v0) {
          ColumnProducts(&wide_ir_[static_cast<size_t>(v - rad) * stride + (start - rad)], stride,
                         &reference_[static_cast<size_t>(v - rad) * columns_ + reference_at],
                         columns_, window, length, products);
        } else {
          const size_t in = static_cast<size_t>(v + rad), out = static_cast<size_t>(v - rad - 1);
          SlideProducts(&wide_ir_[in * stride + (start - rad)],
                        &reference_[in * columns_ + reference_at],
                        &wide_ir_[out * stride + (start - rad)],
                        &reference_[out * columns_ + reference_at], length, products);
        }
      }
      // This row's pixels: their searches' scores, best, second best, verdict.
      int row_lo = std::numeric_limits<int>::max(), row_hi = -1;
      for (int u = start; u < end; ++u) {
        row_lo = std::min(row_lo, s.first[at + u]);
        row_hi = std::max(row_hi, s.last[at + u]);
      }
      const int* first = &s.first[at + start];
      const int* last = &s.last[at + start];
#if MMH_SENSOR_AVX2
      if (UseAvx2().load(std::memory_order_relaxed) &&
          !UseAvx512().load(std::memory_order_relaxed)) {
        // The same scores, every disparity's window sums first.
        for (int d = row_lo; d <= row_hi; ++d) {
          BoxSums(&s.products[static_cast<size_t>(d - lo) * length], window, span, s.box_a.data(),
                  s.box_b.data(), &s.cross[static_cast<size_t>(d - row_lo) * kSegment]);
        }
        const size_t stats_at = static_cast<size_t>(v) * columns_ + (start - row_lo - x_min_);
        ScoreSegmentAvx2(s.cross.data(), &s.sum[at + start], &s.inverse_norm[at + start],
                         &reference_sum_[stats_at], &reference_inverse_norm_[stats_at], n, row_lo,
                         row_hi, first, last, span, kSegment,
                         &s.scores[static_cast<size_t>(row_lo - lo) * kSegment], s.best.data(),
                         s.best_d.data(), s.left.data(), s.right.data(), s.second.data());
      } else  // NOLINT(readability/braces)
#endif
      {
        std::fill_n(s.best.begin(), span, -std::numeric_limits<double>::infinity());
        std::fill_n(s.best_d.begin(), span, -1);
        std::fill_n(s.second.begin(), span, -1.0);
        for (int d = row_lo; d <= row_hi; ++d) {
          BoxSums(&s.products[static_cast<size_t>(d - lo) * length], window, span, s.box_a.data(),
                  s.box_b.data(), s.cross.data());
          const size_t stats_at = static_cast<size_t>(v) * columns_ + (start - d - x_min_);
          double* score = &s.scores[static_cast<size_t>(d - lo) * kSegment];
          ScoreAndTakeBest(s.cross.data(), &s.sum[at + start], &s.inverse_norm[at + start],
                           &reference_sum_[stats_at], &reference_inverse_norm_[stats_at], n, d, first,
                           last, span, d > row_lo ? score - kSegment : s.none.data(), score,
                           s.best.data(), s.best_d.data(), s.left.data(), s.right.data());
        }
        for (int d = row_lo; d <= row_hi; ++d) {
          TakeSecond(&s.scores[static_cast<size_t>(d - lo) * kSegment], d, first, last,
                     s.best_d.data(), span, s.second.data());
        }
      }
      Decide(s.best.data(), s.best_d.data(), s.second.data(), s.left.data(), s.right.data(), first,
             last, &s.pre[at + start], min_correlation, ambiguity, span, s.code.data(),
             s.disparity.data());
      if (!options_.parabola_subpixel) {
        // Where the integer match found the pixel's own surface (within a pixel of its
        // rendered disparity), its rendered disparity; elsewhere (another surface: fattening)
        // the parabola's.
        const size_t p = static_cast<size_t>(v) * w + start;
        for (int k = 0; k < span; ++k) {
          const float rendered = scene.disparity[p + k];
          if (std::abs(static_cast<float>(s.best_d[k]) - rendered) < 1.0f) {
            s.disparity[k] = rendered;
          }
        }
      }
      if (options_.lattice_search) {
        SearchLattice(output, v, start, span, s.code.data(), s.best_d.data(), &s.sum[at + start],
                      &s.inverse_norm[at + start], s.disparity.data());
      }
      if (first_code != nullptr) {
        std::copy_n(s.code.data(), span, first_code + static_cast<size_t>(v) * w + start);
        std::copy_n(s.disparity.data(), span, first_disparity + static_cast<size_t>(v) * w + start);
        continue;
      }
      Output(output, s.code.data(), s.disparity.data(), span,
             depth + static_cast<size_t>(v) * w + start,
             cause != nullptr ? cause + static_cast<size_t>(v) * w + start : nullptr);
    }
  }
}

double SpeckleMatcher::SlantedScore(int u, int v, double d, double g_u, double g_v, double sum,
                                    double inverse_norm) const {
  const int rad = radius_;
  const int stride = width_ + kBlock;
  const double last = samples_ - 2;
  double cross = 0, reference_sum = 0, reference_square = 0;
  for (int j = -rad; j <= rad; ++j) {
    const float* pattern = &pattern_[static_cast<size_t>(v + j) * samples_];
    const int32_t* ir = &wide_ir_[static_cast<size_t>(v + j) * stride + (u - rad)];
    // Window pixel (u + i, v + j) sees the pattern at column u + i - d - g_u i - g_v j.
    const double row_start = u - d - g_v * j - x_min_;
    for (int i = -rad; i <= rad; ++i) {
      double position = (row_start + i * (1.0 - g_u)) * kSubsamples;
      position = std::clamp(position, 0.0, last);
      const int k = static_cast<int>(position);
      const double t = position - k;
      const double b = pattern[k] + t * (pattern[k + 1] - pattern[k]);
      cross += ir[i + rad] * b;
      reference_sum += b;
      reference_square += b * b;
    }
  }
  const double n = static_cast<double>(options_.window_px) * options_.window_px;
  const double norm2 = n * reference_square - reference_sum * reference_sum;
  if (!(norm2 > 0) || !(inverse_norm > 0)) return -std::numeric_limits<double>::infinity();
  return (n * cross - sum * reference_sum) * inverse_norm / std::sqrt(norm2);
}

void SpeckleMatcher::PrepareCentroids() {
  if (!centroids_.empty()) return;
  const int rad = radius_;
  centroid_units_ = std::floor(127.0 / rad);
  centroids_.assign(2 * static_cast<size_t>(height_) * columns_ * kSubsamples, 0);
  const int half = kSubsamples / 2;
  // Each (phase, row) from its own sums in a fixed order: the same for any thread count.
  tbb::parallel_for(
      tbb::blocked_range<int>(0, kSubsamples * height_), [&](const tbb::blocked_range<int>& r) {
        std::vector<double> column(columns_), column_j(columns_);
        for (int task = r.begin(); task != r.end(); ++task) {
          const int q = task / height_, v = task % height_;
          // Down each column: the weight W = (P(k + 1/2 px) - P(k - 1/2 px))^2 at sample k = 8 c +
          // q, and W j, over the window's rows inside the image.
          std::fill(column.begin(), column.end(), 0.0);
          std::fill(column_j.begin(), column_j.end(), 0.0);
          for (int j = -rad; j <= rad; ++j) {
            if (v + j < 0 || v + j >= height_) continue;
            const float* pattern = &pattern_[static_cast<size_t>(v + j) * samples_];
            for (int c = 0; c < columns_; ++c) {
              const int k = c * kSubsamples + q;
              const double slope =
                  pattern[std::min(k + half, samples_ - 1)] - pattern[std::max(k - half, 0)];
              column[c] += slope * slope;
              column_j[c] += slope * slope * j;
            }
          }
          for (int c = 0; c < columns_; ++c) {
            double w = 0, w_i = 0, w_j = 0;
            for (int i = std::max(-rad, -c); i <= std::min(rad, columns_ - 1 - c); ++i) {
              w += column[c + i];
              w_i += column[c + i] * i;
              w_j += column_j[c + i];
            }
            if (!(w > 0)) continue;
            int8_t* out =
                &centroids_[2 * ((static_cast<size_t>(v) * columns_ + c) * kSubsamples + q)];
            out[0] = static_cast<int8_t>(std::lround(centroid_units_ * w_i / w));
            out[1] = static_cast<int8_t>(std::lround(centroid_units_ * w_j / w));
          }
        }
      });
}

void SpeckleMatcher::RefineSlantedRows(const SpeckleOutput& output, int v0, int v1, uint16_t* depth,
                                       MissingCause* cause) const {
  // A plane fit is trusted where it rests on at least half the window and its rms residual is
  // below kMaxResidualPx (a window across a depth edge fits two surfaces badly), its gradient
  // below kMaxGradient [px/px] (about 80 degrees of incidence at 0.75 m).
  constexpr double kMaxResidualPx = 0.5;
  constexpr double kMaxGradient = 0.5;
  // Disparities in 1/kFixed px, so that every sum below is an exact integer.
  constexpr int kFixedInt = 1024;
  constexpr double kFixed = kFixedInt;
  const int w = width_;
  const int rad = radius_;
  const double n = static_cast<double>(options_.window_px) * options_.window_px;
  const bool first_order = options_.slanted_windows == SlantedWindows::kFirstOrder;
  // Down each column over rows y of the window: the matched pixels' count m, sum y, sum y^2, and
  // of their fixed-point disparities q: sum q, sum q y, sum q^2 (kept as the window slides down).
  enum { kM, kY, kYy, kQ, kQy, kQq, kColumnSums };
  std::vector<int64_t> columns(kColumnSums * static_cast<size_t>(w), 0);
  const auto add_row = [&](int y, int sign) {
    const size_t at = static_cast<size_t>(y) * w;
    for (int x = 0; x < w; ++x) {
      if (frame_code_[at + x] != 0) continue;
      // Rounded to nearest (disparities are above -1: the truncation of a positive number).
      const int64_t q =
          static_cast<int64_t>(frame_disparity_[at + x] * kFixed + (kFixed + 0.5)) - kFixedInt;
      int64_t* c = &columns[kColumnSums * static_cast<size_t>(x)];
      c[kM] += sign;
      c[kY] += sign * y;
      c[kYy] += sign * static_cast<int64_t>(y) * y;
      c[kQ] += sign * q;
      c[kQy] += sign * q * y;
      c[kQq] += sign * q * q;
    }
  };
  for (int y = v0 - rad; y < v0 + rad; ++y) add_row(y, 1);
  // Prefix sums along the row of, per column x: m, sum q, x sum q, sum q y, sum q^2 (the rest of
  // a window's moments are constant where all its pixels matched, and summed directly where not).
  enum { kA0, kD0, kD1, kE0, kF0, kPrefixSums };
  std::vector<int64_t> prefix(kPrefixSums * static_cast<size_t>(w + 1), 0);
  std::vector<float> disparity(w);
  // A full window's sum of i^2 (and of j^2): window sum_i i^2.
  const int64_t full_sii = int64_t{options_.window_px} * rad * (rad + 1) * (2 * rad + 1) / 3;
  // Reciprocals: a division per pixel would cost more than the rest of its fit.
  const double inverse_n = 1.0 / n;
  const double inverse_full_sii = 1.0 / static_cast<double>(full_sii);
  const double inverse_units = first_order ? 1.0 / centroid_units_ : 0.0;
  for (int v = v0; v < v1; ++v) {
    add_row(v + rad, 1);
    if (v > v0) add_row(v - rad - 1, -1);
    for (int x = 0; x < w; ++x) {
      const int64_t* c = &columns[kColumnSums * static_cast<size_t>(x)];
      const int64_t* p = &prefix[kPrefixSums * static_cast<size_t>(x)];
      int64_t* next = &prefix[kPrefixSums * static_cast<size_t>(x + 1)];
      next[kA0] = p[kA0] + c[kM];
      next[kD0] = p[kD0] + c[kQ];
      next[kD1] = p[kD1] + x * c[kQ];
      next[kE0] = p[kE0] + c[kQy];
      next[kF0] = p[kF0] + c[kQq];
    }
    const size_t row = static_cast<size_t>(v) * w;
    const int* code = &frame_code_[row];
    std::copy_n(&frame_disparity_[row], w, disparity.data());
    for (int u = rad; u < w - rad; ++u) {
      if (code[u] != 0) continue;
      const int64_t* lo = &prefix[kPrefixSums * static_cast<size_t>(u - rad)];
      const int64_t* hi = &prefix[kPrefixSums * static_cast<size_t>(u + rad + 1)];
      const int64_t s0 = hi[kA0] - lo[kA0];
      if (s0 < 0.5 * n) continue;
      // The window's moments about its centre (i = x - u, j = y - v), exact.
      const int64_t z_d0 = hi[kD0] - lo[kD0];
      const double sd = z_d0 / kFixed;
      const double sid = (hi[kD1] - lo[kD1] - u * z_d0) / kFixed;
      const double sjd = (hi[kE0] - lo[kE0] - v * z_d0) / kFixed;
      const double sdd = (hi[kF0] - lo[kF0]) / (kFixed * kFixed);
      // Least squares d = a + g_u i + g_v j over the window's matched pixels.
      double a, g_u, g_v;
      if (s0 == options_.window_px * options_.window_px) {
        // Every pixel: sum i = sum j = sum i j = 0, sum i^2 = sum j^2 = full_sii.
        a = sd * inverse_n;
        g_u = sid * inverse_full_sii;
        g_v = sjd * inverse_full_sii;
      } else {
        int64_t si = 0, sii = 0, sj = 0, sij = 0, sjj = 0;
        for (int i = -rad; i <= rad; ++i) {
          const int64_t* c = &columns[kColumnSums * static_cast<size_t>(u + i)];
          si += i * c[kM];
          sii += i * i * c[kM];
          sj += c[kY] - v * c[kM];
          sij += i * (c[kY] - v * c[kM]);
          sjj += c[kYy] - 2 * int64_t{v} * c[kY] + int64_t{v} * v * c[kM];
        }
        // Cramer's rule on the normal equations [s0 si sj; si sii sij; sj sij sjj] (a g_u g_v)^T
        // = (sd sid sjd)^T.
        const double m00 = s0, m01 = si, m02 = sj, m11 = sii, m12 = sij, m22 = sjj;
        const double det = m00 * (m11 * m22 - m12 * m12) - m01 * (m01 * m22 - m12 * m02) +
                           m02 * (m01 * m12 - m11 * m02);
        if (!(det > 0.5)) continue;  // an integer determinant: 0 when the pixels are collinear
        const double inverse_det = 1.0 / det;
        a = (sd * (m11 * m22 - m12 * m12) - m01 * (sid * m22 - m12 * sjd) +
             m02 * (sid * m12 - m11 * sjd)) *
            inverse_det;
        g_u = (m00 * (sid * m22 - m12 * sjd) - sd * (m01 * m22 - m12 * m02) +
               m02 * (m01 * sjd - sid * m02)) *
              inverse_det;
        g_v = (m00 * (m11 * sjd - sid * m12) - m01 * (m01 * sjd - sid * m02) +
               sd * (m01 * m12 - m11 * m02)) *
              inverse_det;
      }
      // The residual's sum of squares against kMaxResidualPx^2 times the pixels (no division).
      const double residual_sum = sdd - a * sd - g_u * sid - g_v * sjd;
      if (!(residual_sum <= kMaxResidualPx * kMaxResidualPx * static_cast<double>(s0)) ||
          !(std::abs(g_u) <= kMaxGradient) || !(std::abs(g_v) <= kMaxGradient)) {
        continue;
      }
      const double d1 = disparity[u];
      if (first_order) {
        // d1 >= 0 and u - x_min > max_d: a positive position, rounded by + 0.5.
        const int k = std::min(static_cast<int>((u - d1 - x_min_) * kSubsamples + 0.5),
                               columns_ * kSubsamples - 1);
        // Sample k = 8 c + q of row v: (v columns + c) 8 + q.
        const int8_t* centroid =
            &centroids_[2 * (static_cast<size_t>(v) * columns_ * kSubsamples + k)];
        const double c_u = centroid[0] * inverse_units;
        const double c_v = centroid[1] * inverse_units;
        disparity[u] = static_cast<float>(d1 - (g_u * c_u + g_v * c_v));
      } else {
        disparity[u] = static_cast<float>(ShearedDisparity(output, u, v, d1, g_u, g_v));
      }
    }
    for (int start = 0; start < w; start += kSegment) {
      const int span = std::min(kSegment, w - start);
      Output(output, code + start, disparity.data() + start, span, depth + row + start,
             cause != nullptr ? cause + row + start : nullptr);
    }
  }
}

double SpeckleMatcher::ShearedDisparity(const SpeckleOutput& output, int u, int v, double d1,
                                        double g_u, double g_v) const {
  const int rad = radius_;
  const int window = options_.window_px;
  const double n = static_cast<double>(window) * window;
  const int stride = width_ + kBlock;
  // The IR window's statistics.
  int64_t a_sum = 0, a_square = 0;
  for (int j = -rad; j <= rad; ++j) {
    const int32_t* ir = &wide_ir_[static_cast<size_t>(v + j) * stride + (u - rad)];
    for (int i = 0; i < window; ++i) {
      a_sum += ir[i];
      a_square += static_cast<int64_t>(ir[i]) * ir[i];
    }
  }
  const double a_norm2 =
      n * static_cast<double>(a_square) - static_cast<double>(a_sum) * static_cast<double>(a_sum);
  if (!(a_norm2 > 0)) return d1;
  const double inverse = 1.0 / std::sqrt(a_norm2);
  const auto score = [&](double d) {
    return SlantedScore(u, v, d, g_u, g_v, static_cast<double>(a_sum), inverse);
  };
  // The integer peak beside the first match's, then the three-point Gaussian fit (as Decide).
  int d0 = static_cast<int>(std::floor(d1 + 0.5));
  double left = score(d0 - 1), middle = score(d0), right = score(d0 + 1);
  if (left > middle && left >= right) {
    --d0;
    right = middle;
    middle = left;
    left = score(d0 - 1);
  } else if (right > middle) {
    ++d0;
    left = middle;
    middle = right;
    right = score(d0 + 1);
  }
  const bool positive = left > 0 && middle > 0 && right > 0;
  const double l = positive ? std::log(left) : left;
  const double m = positive ? std::log(middle) : middle;
  const double r = positive ? std::log(right) : right;
  const double curvature = l - 2.0 * m + r;
  double offset = curvature < 0.0 ? 0.5 * (l - r) / curvature : 0.0;
  offset = std::isfinite(offset) ? std::clamp(offset, -0.5, 0.5) : 0.0;
  double refined = d0 + offset;
  if (options_.lattice_search) {
    // The raw lattice value whose sheared reference correlates best: a climb from the fit's.
    const float steps = output.subpixel_steps;
    int raw = static_cast<int>(std::floor(output.raw_offset - steps * refined + 0.5));
    double best = score((output.raw_offset - raw) / steps);
    for (const int step : {1, -1}) {
      bool moved = false;
      for (int tries = 0; tries < kSubsamples; ++tries) {
        const double s = score((output.raw_offset - (raw + step)) / steps);
        if (!(s > best)) break;
        best = s;
        raw += step;
        moved = true;
      }
      if (moved) break;
    }
    refined = (output.raw_offset - raw) / steps;
  }
  return refined;
}

double SpeckleMatcher::LatticeScore(int u, int v, int raw, int32_t sum,
                                   double inverse_norm) const {
  const int rad = radius_;
  const int window = options_.window_px;
  const int stride = width_ + kBlock;
  // Sample index of column u's reference value: (u - x_min) 8 + raw + floor(-raw_offset).
  const int k = (u - x_min_) * kSubsamples + raw + lattice_floor_;
  const int q = k % kSubsamples, c = k / kSubsamples;  // k >= 0: the pattern's margin
  const size_t plane = static_cast<size_t>(height_) * columns_;
  int32_t sums[3];  // exact: window_px^2 (2^adc_bits - 1)^2 < 2^31 (validated)
  WindowProducts(&wide_ir_[static_cast<size_t>(v - rad) * stride + (u - rad)], stride,
                 &lattice_reference_[q * plane + static_cast<size_t>(v - rad) * columns_ +
                                     (c - rad)],
                 columns_, window, sums);
  const int64_t n = static_cast<int64_t>(window) * window;
  const int64_t norm2 = n * sums[2] - static_cast<int64_t>(sums[1]) * sums[1];
  if (norm2 <= 0 || !(inverse_norm > 0)) return -std::numeric_limits<double>::infinity();
  const double numerator =
      static_cast<double>(n * sums[0] - static_cast<int64_t>(sum) * sums[1]);
  return numerator * inverse_norm * (1.0 / std::sqrt(static_cast<double>(norm2)));
}

void SpeckleMatcher::SearchLattice(const SpeckleOutput& output, int v, int start, int n,
                                   const int* code, const int* best_d, const int32_t* sum,
                                   const double* inverse_norm, float* disparity) const {
  const float steps = output.subpixel_steps;
  for (int k = 0; k < n; ++k) {
    if (code[k] != 0) continue;
    const int u = start + k;
    // Raw values within a pixel of the integer match (and inside the pattern's columns).
    const int lowest = static_cast<int>(
        std::ceil(output.raw_offset - steps * static_cast<float>(std::min(best_d[k] + 1, max_d_))));
    const int highest = static_cast<int>(
        std::floor(output.raw_offset - steps * static_cast<float>(std::max(best_d[k] - 1, 0))));
    int raw = static_cast<int>(std::floor(output.raw_offset - steps * disparity[k] + 0.5f));
    raw = std::clamp(raw, lowest, highest);
    double best = LatticeScore(u, v, raw, sum[k], inverse_norm[k]);
    for (const int step : {1, -1}) {
      bool moved = false;
      while (raw + step >= lowest && raw + step <= highest) {
        const double score = LatticeScore(u, v, raw + step, sum[k], inverse_norm[k]);
        if (!(score > best)) break;
        best = score;
        raw += step;
        moved = true;
      }
      if (moved) break;
    }
    disparity[k] = (output.raw_offset - static_cast<float>(raw)) / steps;
  }
}

void SpeckleMatcher::Output(const SpeckleOutput& output, const int* code, const float* disparity,
                            int n, uint16_t* depth, MissingCause* cause) const {
  int32_t units[kSegment], why[kSegment];
  if (output.quantise) {
    LatticeDepth(output, units_by_raw_.data(), code, disparity, n, units, why);
  } else {
    for (int k = 0; k < n; ++k) {
      const float z = output.lattice / (output.subpixel_steps * disparity[k]);
      const bool valid = code[k] == 0 && z >= output.min_depth && z <= output.max_depth;
      units[k] = valid ? static_cast<int32_t>(
                             std::min(65535.0f, std::floor(z * output.inverse_scale + 0.5f)))
                       : 0;
      why[k] = code[k] != 0 ? code[k] : valid ? 0 : static_cast<int>(MissingCause::kRange);
    }
  }
  for (int k = 0; k < n; ++k) depth[k] = static_cast<uint16_t>(units[k]);
  if (cause != nullptr) {
    for (int k = 0; k < n; ++k) cause[k] = static_cast<MissingCause>(why[k]);
  }
}

}  // namespace mmh::sim::internal
