// How animators judge their own animations (the paper's ranking task: each animator ranks their
// three takes and their montage a week after recording them). The paper reports that the
// animators' ranks improve with the order in which the takes were recorded, while the scorers'
// preferences show no take-order effect (H3: F(2, 38) = 0.83); it has "no hypothesis for this
// difference". The harness models it with two documented biases of self-assessment, on top of the
// viewer utility every viewer has (people/viewer.h):
//
//   U_self(item) = U(item) + π · progress(item) + c · [item is the montage]
//
//   progress   take k of K (0-based): k / (K − 1); the montage, made last: 1. Temporal
//              self-appraisal: people rate their earlier selves' work as worse than their later
//              selves' and perceive improvement that an outside judge does not see (Wilson & Ross
//              2001, "From chump to champ", J. Pers. Soc. Psychol. 80(4)); the paper's own
//              speculation ("grew better at acting out stylized motions") is such a belief.
//   montage    the montage is assembled from the parts the animator marked as liked: a
//              choice-supportive bias (Mather, Shafir & Johnson 2000, Psychol. Sci. 11(2)) and the
//              value people put on what they built themselves (Norton, Mochon & Ariely 2012,
//              "The IKEA effect", J. Consum. Psychol. 22(3)).
//
// π and c are in the viewer's utility units (latent quality 0..1). Scorers judge other people's
// animations and have neither bias. With π = c = 0 the animators judge as scorers do (the people
// before the calibration: configs/people/hand_set_2026_11.json).
#pragma once

#include <string>

namespace mmh::people {

// Config section "self_appraisal".
struct SelfAppraisalOptions {
  // Calibrated to the paper's study (docs/calibration.md).
  double progress_weight = 0.177;  // π: utility the animator adds to their last take over the first
  double choice_bonus = 0.177;     // c: utility the animator adds to their montage

  template <class V>
  void VisitFields(V& v) {
    v("progress_weight", progress_weight);
    v("choice_bonus", choice_bonus);
  }
  void Validate(const std::string& prefix) const;
};

// The bias term π · progress + c · [montage] of item `item` of an animator's `takes` takes and
// montage (items 0..takes−1 the takes in recording order, item `takes` the montage).
double SelfAppraisalBias(const SelfAppraisalOptions& options, int item, int takes);

}  // namespace mmh::people
