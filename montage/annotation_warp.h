// Annotations onto the reference timeline: the reaction-time shift and the warp of eq. 6.
#pragma once

#include <span>
#include <string>
#include <utility>
#include <vector>

namespace mmh::montage {

// How many frames the annotation is shifted back: round(reaction_time / frame_period).
// At 30 fps and 0.3 s: 9 frames.
int ReactionShiftFrames(double reaction_time_s, double frame_period_s);

// The value recorded at frame t + shift belongs to frame t (the slider lags the judgement); the
// last `shift` frames repeat the last recorded value. shift >= 0.
std::vector<double> ShiftForReaction(const std::vector<double>& values, int shift);

enum class AnnotationWarpForm {
  // The sum-conserving form of eq. 6 (default): every source frame's value is shared equally among
  // the N reference frames mapped to it (the 1/N of eq. 6), and the values of source frames that
  // the warp skips are added to the reference frame just before the skip (the sum of eq. 6). The
  // warped annotation then sums to exactly the source annotation's sum, the paper's stated intent.
  kConserving,
  // Eq. 6 as printed: a'(t) = sum_{t'=w(t)}^{w(t+1)-1} a(t') when w(t+1) > w(t), a(w(t)) / N when
  // w(t+1) = w(t). The last frame of a flat run counts its source frame again in full; kept for
  // comparison.
  kPaperLiteral,
};
std::span<const std::pair<AnnotationWarpForm, const char*>> EnumNames(AnnotationWarpForm);

// Warped annotation a'_l on the reference timeline (#warp entries) from the source annotation a_l
// (#source frames entries) and the warp w_l (valid: monotone, w(0) = 0, w(n-1) = #source - 1).
std::vector<double> WarpAnnotation(const std::vector<double>& source_values,
                                   const std::vector<int>& warp, AnnotationWarpForm form);

}  // namespace mmh::montage
