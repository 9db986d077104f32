// The tracker's options checked (track/proxy_tracker.h), apart from the tracker so that a program
// that only reads configs (the light mmh: docs/architecture.md, "Start-up") links none of PCL or
// OpenCV.
#include <string>

#include "core/error.h"
#include "track/proxy_tracker.h"

namespace mmh::track {

void DetectionOptions::Validate(const std::string& prefix) const {
  if (yaw_steps < 1 || yaw_steps > 360) {
    ThrowBadValue(prefix + ".yaw_steps", std::to_string(yaw_steps), "an integer in [1, 360]");
  }
  if (coarse_points < 10) {
    ThrowBadValue(prefix + ".coarse_points", std::to_string(coarse_points), ">= 10");
  }
  if (coarse_iterations < 1) {
    ThrowBadValue(prefix + ".coarse_iterations", std::to_string(coarse_iterations), ">= 1");
  }
  if (candidates < 1) ThrowBadValue(prefix + ".candidates", std::to_string(candidates), ">= 1");
  if (refine_points < 10) {
    ThrowBadValue(prefix + ".refine_points", std::to_string(refine_points), ">= 10");
  }
  RequirePositive(coarse_start_distance, prefix + ".coarse_start_distance", "m");
  RequirePositive(coarse_end_distance, prefix + ".coarse_end_distance", "m");
  RequirePositive(recheck_rotation_deg, prefix + ".recheck_rotation_deg", "deg");
  RequirePositive(recheck_translation, prefix + ".recheck_translation", "m");
  if (recheck_interval < 0) {
    ThrowBadValue(prefix + ".recheck_interval", std::to_string(recheck_interval),
                  ">= 0 (0: never)");
  }
  RequireNonNegative(switch_margin, prefix + ".switch_margin");
  RequireNonNegative(far_switch_margin, prefix + ".far_switch_margin");
  RequireNonNegative(rival_drift, prefix + ".rival_drift");
  RequireNonNegative(seed_shift, prefix + ".seed_shift", "m");
  RequireNonNegative(seed_turn_deg, prefix + ".seed_turn_deg", "deg");
  RequireNonNegative(slide_drop, prefix + ".slide_drop");
  RequireNonNegative(rival_threshold, prefix + ".rival_threshold");
  if (model_segments < 0) {
    ThrowBadValue(prefix + ".model_segments", std::to_string(model_segments), ">= 0 (0: off)");
  }
  RequireNonNegative(segment_slack, prefix + ".segment_slack", "m");
  if (!(own_segment_share >= 0 && own_segment_share <= 1)) {
    ThrowBadValue(prefix + ".own_segment_share", FormatNumber(own_segment_share),
                  "in [0, 1] (0: off)");
  }
  if (!(own_segment_distance > 0)) {
    ThrowBadValue(prefix + ".own_segment_distance", FormatNumber(own_segment_distance), "> 0 m");
  }
  if (trusted_frames < 0) {
    ThrowBadValue(prefix + ".trusted_frames", std::to_string(trusted_frames), ">= 0");
  }
  if (reacquire_frames < 0) {
    ThrowBadValue(prefix + ".reacquire_frames", std::to_string(reacquire_frames), ">= 0 (0: off)");
  }
  if (reacquire_trust_frames < 0) {
    ThrowBadValue(prefix + ".reacquire_trust_frames", std::to_string(reacquire_trust_frames),
                  ">= 0 (0: never)");
  }
  RequireProbability(recheck_free_space, prefix + ".recheck_free_space");
  if (coarse_end_distance > coarse_start_distance) {
    ThrowBadValue(prefix + ".coarse_end_distance", FormatNumber(coarse_end_distance),
                  "at most coarse_start_distance");
  }
}

void VerificationOptions::Validate(const std::string& prefix) const {
  if (min_points < 6) ThrowBadValue(prefix + ".min_points", std::to_string(min_points), ">= 6");
  RequireProbability(min_inlier_share, prefix + ".min_inlier_share");
  RequirePositive(max_rms, prefix + ".max_rms", "m");
  RequireProbability(max_free_space_violation, prefix + ".max_free_space_violation");
  RequirePositive(free_space_margin, prefix + ".free_space_margin", "m");
  RequireNonNegative(play_area_margin, prefix + ".play_area_margin", "m");
  if (max_predicted_frames < 0) {
    ThrowBadValue(prefix + ".max_predicted_frames", std::to_string(max_predicted_frames), ">= 0");
  }
  RequireNonNegative(max_penetration, prefix + ".max_penetration", "m");
  RequireNonNegative(skin_distance, prefix + ".skin_distance", "m");
  RequireNonNegative(max_skin_evidence, prefix + ".max_skin_evidence");
  if (max_points < min_points) {
    ThrowBadValue(prefix + ".max_points", std::to_string(max_points), ">= min_points");
  }
}

void ProxyTrackerOptions::Validate(const std::string& prefix) const {
  table.Validate(prefix + ".table");
  segmentation.Validate(prefix + ".segmentation");
  model.Validate(prefix + ".model");
  icp.Validate(prefix + ".icp");
  projective.Validate(prefix + ".projective");
  motion.Validate(prefix + ".motion");
  detection.Validate(prefix + ".detection");
  output_filter.Validate(prefix + ".output_filter");
  verification.Validate(prefix + ".verification");
  appearance.Validate(prefix + ".appearance");
}

}  // namespace mmh::track
