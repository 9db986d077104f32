#include "montage/dtw.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/resource_limits.h"
#include "montage/internal/pose_arrays.h"
#include "montage/match_cost.h"

namespace mmh::montage {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Pruning granularity: blocks of kBlock source frames (64 / kBlock per backtracking word). A
// compile-time knob (-DMMH_DTW_BLOCK=8|16|32); 16 measured fastest on the standard instance
// (8: 10.9 ms, 16: 7.2 ms, 32: 7.2 ms per DTW at the time of the comparison).
#ifndef MMH_DTW_BLOCK
#define MMH_DTW_BLOCK 16
#endif
constexpr int kBlock = MMH_DTW_BLOCK;
constexpr int kBlocksPerWord = 64 / kBlock;

using Clock = std::chrono::steady_clock;

using internal::PoseArrays;

// out[i] = C_match(reference frame t, source frame first + i) for i < count.
MMH_SIMD_CLONES
void CostRun(const PoseArrays& ref, int t, const PoseArrays& src, int first, int count,
             double lambda, double* __restrict out) {
  const double ax = ref.qx[t], ay = ref.qy[t], az = ref.qz[t], aw = ref.qw[t];
  const double atx = ref.tx[t], aty = ref.ty[t], atz = ref.tz[t];
  const double* __restrict bx = src.qx.data() + first;
  const double* __restrict by = src.qy.data() + first;
  const double* __restrict bz = src.qz.data() + first;
  const double* __restrict bw = src.qw.data() + first;
  const double* __restrict btx = src.tx.data() + first;
  const double* __restrict bty = src.ty.data() + first;
  const double* __restrict btz = src.tz.data() + first;
  for (int i = 0; i < count; ++i) {
    out[i] = MatchCost(ax, ay, az, aw, atx, aty, atz, bx[i], by[i], bz[i], bw[i], btx[i], bty[i],
                       btz[i], lambda);
  }
}

// True if no cell of the run can be a new strict prefix minimum: F(t, s) = C(t, s) + M(t-1, s)
// >= `ceiling` for all of them. Uses C >= lambda |x_ref - x_src| and compares squares, so it needs
// no square root. prev[i] = M(t-1, first + i).
MMH_SIMD_CLONES
bool NoNewMinimum(const PoseArrays& ref, int t, const PoseArrays& src, int first, int count,
                  double lambda, double ceiling, const double* __restrict prev) {
  const double atx = ref.tx[t], aty = ref.ty[t], atz = ref.tz[t];
  const double lambda2 = lambda * lambda;
  const double* __restrict btx = src.tx.data() + first;
  const double* __restrict bty = src.ty.data() + first;
  const double* __restrict btz = src.tz.data() + first;
  // An integer OR reduction (a bool AND does not vectorise); full blocks get a constant trip count.
  auto any_may_lower = [&](int n) {
    long hits = 0;
    for (int i = 0; i < n; ++i) {
      const double ex = atx - btx[i], ey = aty - bty[i], ez = atz - btz[i];
      const double slack = ceiling - prev[i];
      hits |= static_cast<long>(slack > 0.0) &
              static_cast<long>(lambda2 * (ex * ex + ey * ey + ez * ez) < slack * slack);
    }
    return hits != 0;
  };
  return count == kBlock ? !any_may_lower(kBlock) : !any_may_lower(count);
}

// ---------------------------------------------------------------------------------------------
// Lower bounds for pruning. Each block of kBlock source frames is enclosed in two balls: one in
// R^4 around its quaternions (each taken with the sign closest to the block's first one) and one
// in R^3 around its translations. By the triangle inequality, for every source frame s in block j
//   C_match(A, T_src(s)) >= max(0, min(|q - c_j|, |q + c_j|) - r_j) + lambda max(0, |x - m_j| -
//   R_j).
struct BlockBalls {
  std::vector<double> cx, cy, cz, cw, rq, mx, my, mz, rt;
  // The same in single precision (radii rounded up) for the fast bound rows, and the bound on
  // their rounding error (see LowerBoundRowFloat).
  std::vector<float> fcx, fcy, fcz, fcw, frq, fmx, fmy, fmz, frt;
  double float_margin = 0.0;
};

BlockBalls MakeBlockBalls(const PoseArrays& src) {
  const int n = src.size();
  const int blocks = (n + kBlock - 1) / kBlock;
  BlockBalls b;
  for (auto* v : {&b.cx, &b.cy, &b.cz, &b.cw, &b.rq, &b.mx, &b.my, &b.mz, &b.rt}) v->resize(blocks);
  for (int j = 0; j < blocks; ++j) {
    const int first = j * kBlock, last = std::min(n, first + kBlock);
    const double inv = 1.0 / (last - first);
    std::array<double, 4> c{0, 0, 0, 0};
    std::array<double, 3> m{0, 0, 0};
    std::array<double, 4> q0{src.qx[first], src.qy[first], src.qz[first], src.qw[first]};
    auto aligned = [&](int s) {
      std::array<double, 4> q{src.qx[s], src.qy[s], src.qz[s], src.qw[s]};
      const double dot = q[0] * q0[0] + q[1] * q0[1] + q[2] * q0[2] + q[3] * q0[3];
      if (dot < 0) {
        for (auto& v : q) v = -v;
      }
      return q;
    };
    for (int s = first; s < last; ++s) {
      const auto q = aligned(s);
      for (int k = 0; k < 4; ++k) c[k] += q[k] * inv;
      m[0] += src.tx[s] * inv;
      m[1] += src.ty[s] * inv;
      m[2] += src.tz[s] * inv;
    }
    double rq = 0, rt = 0;
    for (int s = first; s < last; ++s) {
      const auto q = aligned(s);
      double dq = 0;
      for (int k = 0; k < 4; ++k) dq += (q[k] - c[k]) * (q[k] - c[k]);
      const double dx = src.tx[s] - m[0], dy = src.ty[s] - m[1], dz = src.tz[s] - m[2];
      rq = std::max(rq, std::sqrt(dq));
      rt = std::max(rt, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
    // Inflate the radii a little so that rounding can never make a bound exceed the true cost.
    b.cx[j] = c[0], b.cy[j] = c[1], b.cz[j] = c[2], b.cw[j] = c[3];
    b.mx[j] = m[0], b.my[j] = m[1], b.mz[j] = m[2];
    b.rq[j] = rq * (1 + 1e-9) + 1e-12;
    b.rt[j] = rt * (1 + 1e-9) + 1e-12;
  }
  auto to_float = [](const std::vector<double>& v, double scale) {
    std::vector<float> f(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) f[i] = static_cast<float>(v[i] * scale);
    return f;
  };
  // Radii scaled up by 2^-20 so that the conversion (relative error <= 2^-24) never shrinks them.
  b.fcx = to_float(b.cx, 1), b.fcy = to_float(b.cy, 1), b.fcz = to_float(b.cz, 1);
  b.fcw = to_float(b.cw, 1), b.fmx = to_float(b.mx, 1), b.fmy = to_float(b.my, 1);
  b.fmz = to_float(b.mz, 1), b.frq = to_float(b.rq, 1 + 0x1p-20),
  b.frt = to_float(b.rt, 1 + 0x1p-20);
  return b;
}

// Sets the margin of the single-precision bounds for a reference take: with u = 2^-24 and X the
// largest translation coordinate of the reference and the block centres, the float rotation term
// is within 30u of its exact value and the translation term within 40uX + 8u, so subtracting
// 64u (1 + lambda (1 + 2X)) keeps every float bound below the double one.
void SetFloatMargin(const PoseArrays& ref, double lambda, BlockBalls* b) {
  double x = 0.0;
  const BlockBalls& c = *b;
  for (const std::vector<double>* v : {&ref.tx, &ref.ty, &ref.tz, &c.mx, &c.my, &c.mz}) {
    for (double c : *v) x = std::max(x, std::abs(c));
  }
  b->float_margin = 64 * 0x1p-24 * (1 + lambda * (1 + 2 * x));
}

// out[j] = a lower bound of C_match(reference frame t, any source frame of block j), j in
// [first, last), computed in single precision (twice the lanes, cheaper square roots) and
// lowered by the rounding margin of SetFloatMargin.
MMH_SIMD_CLONES
void LowerBoundRowFloat(const PoseArrays& ref, int t, const BlockBalls& b, int first, int last,
                        double lambda, double* __restrict out) {
  const float ax = static_cast<float>(ref.qx[t]), ay = static_cast<float>(ref.qy[t]);
  const float az = static_cast<float>(ref.qz[t]), aw = static_cast<float>(ref.qw[t]);
  const float atx = static_cast<float>(ref.tx[t]), aty = static_cast<float>(ref.ty[t]);
  const float atz = static_cast<float>(ref.tz[t]);
  const float flambda = static_cast<float>(lambda);
  const double margin = b.float_margin;
  const float* __restrict cx = b.fcx.data();
  const float* __restrict cy = b.fcy.data();
  const float* __restrict cz = b.fcz.data();
  const float* __restrict cw = b.fcw.data();
  const float* __restrict mx = b.fmx.data();
  const float* __restrict my = b.fmy.data();
  const float* __restrict mz = b.fmz.data();
  const float* __restrict rq = b.frq.data();
  const float* __restrict rt = b.frt.data();
  for (int j = first; j < last; ++j) {
    const float dx = ax - cx[j], dy = ay - cy[j], dz = az - cz[j], dw = aw - cw[j];
    const float sx = ax + cx[j], sy = ay + cy[j], sz = az + cz[j], sw = aw + cw[j];
    const float q = std::sqrt(
        std::min(dx * dx + dy * dy + dz * dz + dw * dw, sx * sx + sy * sy + sz * sz + sw * sw));
    const float ex = atx - mx[j], ey = aty - my[j], ez = atz - mz[j];
    const float x = std::sqrt(ex * ex + ey * ey + ez * ez);
    const float lb = std::max(0.0f, q - rq[j]) + flambda * std::max(0.0f, x - rt[j]);
    out[j] = std::max(0.0, static_cast<double>(lb) - margin);
  }
}

// out[i] = a float not above x[i] (x[i] >= 0 or +inf): shrinking by 2^-20 first leaves room for
// the conversion's rounding (at most 2^-24 relative).
void StoreBelow(const double* x, int count, float* out) {
  for (int i = 0; i < count; ++i) out[i] = static_cast<float>(x[i] * (1.0 - 0x1p-20));
}

// ---------------------------------------------------------------------------------------------
// The literal dynamic programme (eq. 4):
//   F(0, 0) = C(0, 0), F(0, s > 0) = inf,  F(t, s) = C(t, s) + min_{s' <= s} F(t-1, s'),
// cost F(n-1, N-1), backtracking w(t-1) = argmin_{s' <= w(t)} F(t-1, s') (first minimum).
// Cells of blocks marked dead are taken as +inf (never evaluated). One bit per cell records "F(t,
// s) is a new strict prefix minimum of row t", so the argmin is the last set bit at or before w(t):
// the backtracking store is n * N bits, never a matrix of doubles.
class LiteralProgramme {
 public:
  LiteralProgramme(const PoseArrays& ref, const PoseArrays& src, double lambda)
      : ref_(ref),
        src_(src),
        lambda_(lambda),
        n_(ref.size()),
        big_n_(src.size()),
        blocks_((big_n_ + kBlock - 1) / kBlock),
        words_((big_n_ + 63) / 64) {}

  // The pruning policy: `pruner.Range(t)` gives the blocks [first, last] of row t worth visiting
  // (blocks outside are +inf); `pruner.BeginRow(t, first, last)` is called before a row's visit;
  // `pruner.Live(t, j, m)` says whether block j of row t may hold an optimal cell, given
  // m = M(t-1, end of block j), the least prefix minimum of the previous row over the block.
  // Returns the cost (inf if no warp runs through live cells only) and fills `warp`.
  template <class Pruner>
  double Run(Pruner& pruner, std::vector<int>* warp, std::int64_t* evaluated) {
    bits_.assign(static_cast<std::size_t>(n_) * words_, 0);
    m_prev_.resize(big_n_);
    m_cur_.resize(big_n_);
    end_prev_.assign(blocks_, kInf);
    end_cur_.assign(blocks_, kInf);
    live_prev_.assign(blocks_, 0);
    live_cur_.assign(blocks_, 0);
    std::array<double, 2 * kBlock> cost{};
    double last_f = kInf;  // F(n-1, N-1)

    // Row 0: only w(0) = 0 is allowed; the prefix minimum is C(0, 0) along the whole row.
    const double c0 = Cost(0, 0, cost.data());
    ++*evaluated;
    for (int s = 0; s < std::min(big_n_, kBlock); ++s) m_prev_[s] = c0;
    end_prev_[0] = c0;
    live_prev_[0] = 1;
    bits_[0] = 1;
    int prev_first = 0, prev_last = 0;  // previous row: first live block, last visited block
    double prev_tail = c0;              // its prefix minimum after prev_last
    if (n_ == 1) last_f = big_n_ == 1 ? c0 : kInf;

    for (int t = 1; t < n_; ++t) {
      auto [first_block, last_block] = pruner.Range(t);
      // Before the previous row's first live block every cell of row t-1 is +inf.
      first_block = std::max(first_block, prev_first);
      pruner.BeginRow(t, first_block, last_block);
      double carry = kInf;  // prefix minimum of row t so far
      int first_live = -1;  // first block of row t holding a finite value
      std::uint64_t* row_bits = bits_.data() + static_cast<std::size_t>(t) * words_;
      auto end_of_prev = [&](int j) {
        return j < prev_first ? kInf : (j > prev_last ? prev_tail : end_prev_[j]);
      };
      for (int j = first_block; j <= last_block; ++j) {
        const int first = j * kBlock;
        const int count = std::min(kBlock, big_n_ - first);
        const bool prev_live = j >= prev_first && j <= prev_last && live_prev_[j];
        const double before = j == 0 ? kInf : end_of_prev(j - 1);
        if ((!prev_live && before == kInf) || !pruner.Live(t, j, end_of_prev(j))) {
          live_cur_[j] = 0;
          end_cur_[j] = carry;
          continue;
        }
        const double* prev = m_prev_.data() + first;
        if (!prev_live) {
          std::fill(cost.begin(), cost.begin() + count, before);
          prev = cost.data();
        }
        // A block that cannot lower the row's prefix minimum leaves it (and its bits) as they
        // are. The margin of 1e-12 of the running cost dwarfs the rounding of F = C + M, so the
        // result is bit-identical to evaluating every cell. The last cell's F is always needed.
        if (carry < kInf && !(t == n_ - 1 && first + count == big_n_) &&
            NoNewMinimum(ref_, t, src_, first, count, lambda_, carry * (1 + 1e-12), prev)) {
          double* cur = m_cur_.data() + first;
          for (int i = 0; i < count; ++i) cur[i] = carry;
          live_cur_[j] = 1;
          end_cur_[j] = carry;
          if (first_live < 0) first_live = j;
          continue;
        }
        CostRun(ref_, t, src_, first, count, lambda_, cost.data() + kBlock);
        *evaluated += count;
        for (int i = 0; i < count; ++i) cost[i] = cost[kBlock + i] + prev[i];
        std::uint64_t mask = 0;
        double* cur = m_cur_.data() + first;
        for (int i = 0; i < count; ++i) {
          const double f = cost[i];
          const bool lower = f < carry;
          carry = lower ? f : carry;
          mask |= static_cast<std::uint64_t>(lower) << i;
          cur[i] = carry;
        }
        if (t == n_ - 1 && first + count == big_n_) last_f = cost[count - 1];
        row_bits[j / kBlocksPerWord] |= mask << (kBlock * (j % kBlocksPerWord));
        live_cur_[j] = 1;
        end_cur_[j] = carry;
        if (first_live < 0) first_live = j;
      }
      std::swap(m_prev_, m_cur_);
      std::swap(end_prev_, end_cur_);
      std::swap(live_prev_, live_cur_);
      if (first_live < 0) return kInf;  // nothing of row t is reachable
      // Blocks of row t before its first live one are +inf: row t+1 starts there.
      prev_first = first_live;
      prev_last = last_block;
      prev_tail = carry;
    }
    if (!(last_f < kInf)) return kInf;
    warp->assign(n_, 0);
    (*warp)[n_ - 1] = big_n_ - 1;
    for (int t = n_ - 1; t >= 1; --t) (*warp)[t - 1] = LastMinimumAtOrBefore(t - 1, (*warp)[t]);
    return last_f;
  }

 private:
  double Cost(int t, int s, double* scratch) const {
    CostRun(ref_, t, src_, s, 1, lambda_, scratch);
    return scratch[0];
  }

  int LastMinimumAtOrBefore(int t, int s) const {
    const std::uint64_t* row_bits = bits_.data() + static_cast<std::size_t>(t) * words_;
    int word = s / 64;
    std::uint64_t bits = row_bits[word] & (~std::uint64_t{0} >> (63 - s % 64));
    while (bits == 0) {
      if (--word < 0) return 0;  // not reached for a finite cost: F(t, 0..s) has a minimum
      bits = row_bits[word];
    }
    return word * 64 + 63 - std::countl_zero(bits);
  }

  const PoseArrays& ref_;
  const PoseArrays& src_;
  double lambda_;
  int n_, big_n_, blocks_, words_;
  std::vector<std::uint64_t> bits_;
  std::vector<double> m_prev_, m_cur_, end_prev_, end_cur_;
  std::vector<char> live_prev_, live_cur_;
};

// Pruning policies for LiteralProgramme::Run.
struct NoPruning {
  int blocks;
  std::pair<int, int> Range(int) const { return {0, blocks - 1}; }
  void BeginRow(int, int, int) {}
  bool Live(int, int, double) const { return true; }
};
struct BandPruning {
  const std::vector<int>& first;
  const std::vector<int>& last;
  std::pair<int, int> Range(int t) const { return {first[t], last[t]}; }
  void BeginRow(int, int, int) {}
  bool Live(int, int, double) const { return true; }
};

// The pruned literal DTW, exact. With lb(t, j) <= C(t, s) for s in block j (BlockBalls) and the
// backward bound
//   BL(t, j) <= cost of rows t+1..n-1 after any s in block j:
//   BL(n-1, last block) = 0, BL(t, j) = min_{j' >= j} lb(t+1, j') + BL(t+1, j'),
// a cell (t, s) of block j can only lie on a warp of cost <= U if
//   lb(t, j) + M(t-1, end of block j) + BL(t, j) <= U,
// where M(t-1, .) is the programme's own prefix minimum of the previous row (exact on every
// optimal warp's cells, by induction over t). U is the cost of a feasible warp: the literal
// programme on every 8th frame, refined in a band of +-24 frames around it. Every optimal warp
// keeps all its cells live, and so does every first-minimum backtracking candidate, so the result
// is the full programme's, warp for warp.
double PrunedLiteral(const PoseArrays& ref, const PoseArrays& src, double lambda,
                     std::vector<int>* warp, std::int64_t* evaluated) {
  const int n = ref.size(), big_n = src.size();
  const int blocks = (big_n + kBlock - 1) / kBlock;
  BlockBalls balls = MakeBlockBalls(src);
  SetFloatMargin(ref, lambda, &balls);

  // 1. Upper bound U: a coarse warp on every kCoarse-th frame (both ends kept), then the exact
  // programme in a band of +-kRadius frames around it.
  constexpr int kCoarse = 8, kRadius = 24;
  auto subsample = [](int frames) {
    std::vector<int> index;
    for (int i = 0; i < frames - 1; i += kCoarse) index.push_back(i);
    index.push_back(frames - 1);
    return index;
  };
  const std::vector<int> ref_index = subsample(n), src_index = subsample(big_n);
  const PoseArrays coarse_ref = PoseArrays::Subset(ref, ref_index);
  const PoseArrays coarse_src = PoseArrays::Subset(src, src_index);
  std::vector<int> coarse_warp;  // n >= 2 here, so both subsamples have >= 2 frames
  LiteralProgramme coarse(coarse_ref, coarse_src, lambda);
  NoPruning all_coarse{(coarse_src.size() + kBlock - 1) / kBlock};
  coarse.Run(all_coarse, &coarse_warp, evaluated);
  std::vector<int> band_first(n), band_last(n);
  for (int t = 0; t < n; ++t) {
    const int i = std::min(static_cast<int>(ref_index.size()) - 1, (t + kCoarse / 2) / kCoarse);
    const int centre = src_index[coarse_warp[i]];
    band_first[t] = std::max(0, centre - kRadius) / kBlock;
    band_last[t] = std::min(big_n - 1, centre + kRadius) / kBlock;
  }
  // The band's first blocks must not decrease (then staying on them is a warp) and the last row
  // must reach the last block.
  for (int t = 1; t < n; ++t) band_first[t] = std::max(band_first[t], band_first[t - 1]);
  for (int t = 0; t < n; ++t) band_last[t] = std::max(band_last[t], band_first[t]);
  band_last[n - 1] = blocks - 1;
  LiteralProgramme programme(ref, src, lambda);
  std::vector<int> band_warp;
  BandPruning band{band_first, band_last};
  const double upper = programme.Run(band, &band_warp, evaluated);
  // Margin for the rounding of the bounds' sums.
  const double threshold = upper * (1 + 1e-9) + 1e-9;

  // 2. Backward bounds BL(t, j), as floats rounded down (#n by #blocks). BL is non-decreasing in
  // j, so blocks past last_useful[t] (BL > U) are dead, and the terms they feed into row t-1 are
  // > U as well: each row only needs the blocks up to the next row's last useful one.
  std::vector<float> backward(static_cast<std::size_t>(n) * blocks);
  std::vector<int> last_useful(n, blocks - 1);
  std::vector<double> lb_row(blocks), acc(blocks, kInf);
  acc[blocks - 1] = 0.0;
  for (int t = n - 1; t >= 0; --t) {
    const int limit = last_useful[t];
    StoreBelow(acc.data(), limit + 1, backward.data() + static_cast<std::size_t>(t) * blocks);
    if (t == 0) break;
    LowerBoundRowFloat(ref, t, balls, 0, limit + 1, lambda, lb_row.data());
    double suffix = kInf;
    for (int j = limit; j >= 0; --j) {
      suffix = std::min(suffix, lb_row[j] + acc[j]);
      acc[j] = suffix;
    }
    int last = limit;
    while (last > 0 && !(acc[last] <= threshold)) --last;
    last_useful[t - 1] = last;
  }

  // 3. The exact programme over the blocks that may hold an optimal cell.
  struct BoundPruning {
    const PoseArrays& ref;
    const BlockBalls& balls;
    const std::vector<float>& backward;
    const std::vector<int>& last_useful;
    std::vector<double>& lb_row;
    int blocks;
    double lambda, threshold;
    std::pair<int, int> Range(int t) const { return {0, last_useful[t]}; }
    void BeginRow(int t, int first, int last) {
      if (last >= first) {
        LowerBoundRowFloat(ref, t, balls, first, last + 1, lambda, lb_row.data());
      }
    }
    bool Live(int t, int j, double before_end) const {
      return before_end + static_cast<double>(backward[static_cast<std::size_t>(t) * blocks + j]) +
                 lb_row[j] <=
             threshold;
    }
  } bound{ref, balls, backward, last_useful, lb_row, blocks, lambda, threshold};
  const double cost = programme.Run(bound, warp, evaluated);
  if (cost < kInf) return cost;
  // Unreachable by the argument above; kept so that a bound bug can never lose the warp.
  NoPruning all{blocks};
  return programme.Run(all, warp, evaluated);
}

// ---------------------------------------------------------------------------------------------
// The other step patterns: full programmes with one byte of backtracking per cell.
double SlopeLimited(const PoseArrays& ref, const PoseArrays& src, double lambda,
                    std::vector<int>* warp, std::int64_t* evaluated) {
  const int n = ref.size(), big_n = src.size();
  std::vector<std::uint8_t> step(static_cast<std::size_t>(n) * big_n, 0);
  std::vector<double> prev(big_n, kInf), cur(big_n), cost(big_n);
  CostRun(ref, 0, src, 0, big_n, lambda, cost.data());
  prev[0] = cost[0];
  for (int t = 1; t < n; ++t) {
    CostRun(ref, t, src, 0, big_n, lambda, cost.data());
    for (int s = 0; s < big_n; ++s) {
      double best = prev[s];
      std::uint8_t k = 0;
      for (std::uint8_t d = 1; d <= 2 && d <= s; ++d) {
        if (prev[s - d] < best) {
          best = prev[s - d];
          k = d;
        }
      }
      cur[s] = cost[s] + best;
      step[static_cast<std::size_t>(t) * big_n + s] = k;
    }
    std::swap(prev, cur);
  }
  *evaluated += static_cast<std::int64_t>(n) * big_n;
  warp->assign(n, 0);
  (*warp)[n - 1] = big_n - 1;
  for (int t = n - 1; t >= 1; --t) {
    (*warp)[t - 1] = (*warp)[t] - step[static_cast<std::size_t>(t) * big_n + (*warp)[t]];
  }
  return prev[big_n - 1];
}

double Symmetric(const PoseArrays& ref, const PoseArrays& src, double lambda,
                 std::vector<int>* warp, std::int64_t* evaluated) {
  // D(t, s) = C(t, s) + min(D(t-1, s-1), D(t-1, s), D(t, s-1)); moves: 0 diagonal, 1 from the row
  // above, 2 from the left.
  const int n = ref.size(), big_n = src.size();
  std::vector<std::uint8_t> move(static_cast<std::size_t>(n) * big_n, 0);
  std::vector<double> prev(big_n, kInf), cur(big_n), cost(big_n);
  for (int t = 0; t < n; ++t) {
    CostRun(ref, t, src, 0, big_n, lambda, cost.data());
    for (int s = 0; s < big_n; ++s) {
      double best = kInf;
      // The default move stays inside the matrix even when every predecessor is +inf: the walk
      // back must never leave it (on row 0 only "from the left", on column 0 only "from above").
      std::uint8_t k = t == 0 ? 2 : (s == 0 ? 1 : 0);
      if (t == 0 && s == 0) best = 0;
      if (t > 0 && s > 0 && prev[s - 1] < best) best = prev[s - 1], k = 0;
      if (t > 0 && prev[s] < best) best = prev[s], k = 1;
      if (s > 0 && cur[s - 1] < best) best = cur[s - 1], k = 2;
      cur[s] = cost[s] + best;
      move[static_cast<std::size_t>(t) * big_n + s] = k;
    }
    std::swap(prev, cur);
  }
  *evaluated += static_cast<std::int64_t>(n) * big_n;
  // Walk back; w(t) = the smallest s of the path in row t, and w(n-1) = N-1 (eq. 3), so that the
  // annotation warp (eq. 6) sees every source frame.
  warp->assign(n, 0);
  int t = n - 1, s = big_n - 1;
  while (t > 0 || s > 0) {
    (*warp)[t] = s;
    const std::uint8_t k = move[static_cast<std::size_t>(t) * big_n + s];
    if (k == 0)
      --t, --s;
    else if (k == 1)
      --t;
    else
      --s;
  }
  (*warp)[0] = 0;
  (*warp)[n - 1] = big_n - 1;
  return prev[big_n - 1];
}

constexpr std::pair<StepPattern, const char*> kStepPatternNames[] = {
    {StepPattern::kLiteral, "literal"},
    {StepPattern::kSlopeLimited, "slope_limited"},
    {StepPattern::kSymmetric, "symmetric"},
};

}  // namespace

std::span<const std::pair<StepPattern, const char*>> EnumNames(StepPattern) {
  return kStepPatternNames;
}

void DtwOptions::Validate(const std::string& prefix) const {
  if (!std::isfinite(lambda) || lambda < 0) {
    ThrowBadValue(prefix + ".lambda", FormatNumber(lambda), "a finite number >= 0");
  }
}

DtwResult ComputeDtw(const Trajectory& reference, const Trajectory& source,
                     const DtwOptions& options) {
  const auto start = Clock::now();
  const int n = static_cast<int>(reference.size());
  const int big_n = static_cast<int>(source.size());
  if (n == 0 || big_n == 0) {
    ThrowBadValue("DTW",
                  std::to_string(n) + " reference and " + std::to_string(big_n) + " source frames",
                  "non-empty takes");
  }
  if (n == 1 && big_n > 1) {
    ThrowBadValue("DTW", "a reference of 1 frame and a source of " + std::to_string(big_n),
                  "a warp with w(0) = 0 and w(n-1) = N-1 (eq. 3), impossible for n = 1 < N");
  }
  if (options.step_pattern == StepPattern::kSlopeLimited && big_n - 1 > 2 * (n - 1)) {
    ThrowBadValue(
        "DTW (step_pattern slope_limited)",
        "a source of " + std::to_string(big_n) + " frames for a reference of " + std::to_string(n),
        "a source at most 2 (n - 1) + 1 frames long");
  }
  // Translations beyond kMaxTranslationMetres can overflow the costs (1e200^2 = inf).
  // (Only the values: callers may pass poses without timestamps.)
  for (const auto& [take, name] : {std::pair{&reference, "reference"}, {&source, "source"}}) {
    for (std::size_t i = 0; i < take->size(); ++i) {
      const Rigid3& pose = take->poses[i];
      if (!pose.rotation.coeffs().allFinite() || !pose.translation.allFinite() ||
          pose.translation.cwiseAbs().maxCoeff() > kMaxTranslationMetres) {
        ThrowBadValue(std::string("DTW ") + name + " take, frame " + std::to_string(i),
                      "translation (" + FormatNumber(pose.translation.x()) + ", " +
                          FormatNumber(pose.translation.y()) + ", " +
                          FormatNumber(pose.translation.z()) + ")",
                      "finite values within +-1e6 m (kMaxTranslationMetres) and a finite "
                      "quaternion");
      }
    }
  }
  const PoseArrays ref(reference), src(source);
  DtwResult result;
  result.summary.cells_total = static_cast<std::int64_t>(n) * big_n;
  std::int64_t evaluated = 0;
  double cost = kInf;
  switch (options.step_pattern) {
    case StepPattern::kLiteral: {
      // Small problems: the full programme is as fast as bounding it.
      if (options.prune && static_cast<std::int64_t>(n) * big_n > 64 * 64) {
        cost = PrunedLiteral(ref, src, options.lambda, &result.warp, &evaluated);
      } else {
        LiteralProgramme programme(ref, src, options.lambda);
        NoPruning all{(src.size() + kBlock - 1) / kBlock};
        cost = programme.Run(all, &result.warp, &evaluated);
      }
      break;
    }
    case StepPattern::kSlopeLimited:
      cost = SlopeLimited(ref, src, options.lambda, &result.warp, &evaluated);
      break;
    case StepPattern::kSymmetric:
      cost = Symmetric(ref, src, options.lambda, &result.warp, &evaluated);
      break;
  }
  // Every cost is finite for poses within kMaxTranslationMetres; an infinite optimum (costs that
  // overflowed) has no meaningful warp, and the literal programme returns none.
  if (!std::isfinite(cost) || static_cast<int>(result.warp.size()) != n) {
    ThrowBadValue(
        "DTW (step_pattern " +
            std::string(kStepPatternNames[static_cast<int>(options.step_pattern)].second) + ")",
        "a warp cost of " + FormatNumber(cost),
        "finite matching costs (eq. 5): poses with finite translations within +-" +
            FormatNumber(kMaxTranslationMetres) + " m and finite quaternions");
  }
  result.summary.cost = cost;
  result.summary.cells_evaluated = evaluated;
  result.summary.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

double WarpCost(const Trajectory& reference, const Trajectory& source, const std::vector<int>& warp,
                double lambda) {
  double cost = 0.0;
  for (std::size_t t = 0; t < warp.size(); ++t) {
    cost += MatchCost(reference.poses[t], source.poses[warp[t]], lambda);
  }
  return cost;
}

bool IsValidWarp(const std::vector<int>& warp, int source_frames, StepPattern pattern) {
  if (warp.empty() || warp.front() != 0 || warp.back() != source_frames - 1) return false;
  for (std::size_t t = 1; t < warp.size(); ++t) {
    const int step = warp[t] - warp[t - 1];
    if (step < 0 || warp[t] >= source_frames) return false;
    if (pattern == StepPattern::kSlopeLimited && step > 2) return false;
  }
  return true;
}

}  // namespace mmh::montage
