#include "montage/annotation_warp.h"

#include <cmath>

#include "core/error.h"

namespace mmh::montage {
namespace {

constexpr std::pair<AnnotationWarpForm, const char*> kFormNames[] = {
    {AnnotationWarpForm::kConserving, "conserving"},
    {AnnotationWarpForm::kPaperLiteral, "paper_literal"},
};

}  // namespace

std::span<const std::pair<AnnotationWarpForm, const char*>> EnumNames(AnnotationWarpForm) {
  return kFormNames;
}

int ReactionShiftFrames(double reaction_time_s, double frame_period_s) {
  if (!(frame_period_s > 0) || !(reaction_time_s >= 0)) return 0;
  return static_cast<int>(std::lround(reaction_time_s / frame_period_s));
}

std::vector<double> ShiftForReaction(const std::vector<double>& values, int shift) {
  std::vector<double> shifted(values.size());
  if (values.empty()) return shifted;
  const std::size_t n = values.size();
  for (std::size_t t = 0; t < n; ++t) {
    const std::size_t from = t + static_cast<std::size_t>(shift);
    shifted[t] = from < n ? values[from] : values.back();
  }
  return shifted;
}

std::vector<double> WarpAnnotation(const std::vector<double>& source_values,
                                   const std::vector<int>& warp, AnnotationWarpForm form) {
  const int n = static_cast<int>(warp.size());
  const int big_n = static_cast<int>(source_values.size());
  if (n == 0 || warp.front() != 0 || warp.back() != big_n - 1) {
    ThrowBadValue("annotation warp",
                  "a warp of " + std::to_string(n) + " frames ending at " +
                      (n ? std::to_string(warp.back()) : std::string("-")),
                  "a warp from 0 to " + std::to_string(big_n - 1));
  }
  std::vector<double> warped(n, 0.0);
  int t = 0;
  while (t < n) {
    // The run of reference frames [t, end) that share the source frame s (N_{w(t)} of eq. 6).
    const int s = warp[t];
    int end = t + 1;
    while (end < n && warp[end] == s) ++end;
    const int run = end - t;
    const int next = end < n ? warp[end] : big_n;  // first source frame of the next run
    if (form == AnnotationWarpForm::kConserving) {
      // Share a(s) over the run, then give the skipped source frames (s, next) to the run's last
      // frame: sum_t a'(t) = sum_s a(s).
      for (int i = t; i < end; ++i) warped[i] = source_values[s] / run;
      double skipped = 0.0;
      for (int k = s + 1; k < next; ++k) skipped += source_values[k];
      warped[end - 1] += skipped;
    } else {
      // Eq. 6 as printed: a(w(t))/N on the flat part, sum_{w(t)}^{w(t+1)-1} a at the step.
      for (int i = t; i < end; ++i) {
        if (i + 1 < n && warp[i + 1] == warp[i]) {
          warped[i] = source_values[s] / run;
        } else {
          double sum = 0.0;
          const int stop = i + 1 < n ? warp[i + 1] : big_n;
          for (int k = s; k < stop; ++k) sum += source_values[k];
          warped[i] = sum;
        }
      }
    }
    t = end;
  }
  return warped;
}

}  // namespace mmh::montage
