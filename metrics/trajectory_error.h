// Trajectory errors as the `evo` tool reports them (Grupp 2017, github.com/MichaelGrupp/evo):
// the absolute pose error (APE, also called ATE) and the relative pose error (RPE, Sturm et al.
// 2012), each summarised by evo's statistics: rmse, mean, median, std (population), min, max, sse.
// Both trajectories are in the same frame (the table frame: no alignment is needed, the setup is
// calibrated), frame i of one belonging to frame i of the other.
#pragma once

#include <nlohmann/json.hpp>
#include <span>
#include <vector>

#include "core/rigid3.h"

namespace mmh::metrics {

// evo's statistics of a list of errors (keys in evo's names).
struct ErrorStatistics {
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;  // population standard deviation (numpy's default)
  double min = 0.0;
  double max = 0.0;
  double sse = 0.0;  // sum of squares
  int count = 0;
};
ErrorStatistics Statistics(std::span<const double> errors);
nlohmann::json ToJson(const ErrorStatistics& statistics);

// APE of the translation part [m], per frame: ‖t(ref_i) − t(est_i)‖ (evo_ape's default
// "translation_part"). Sizes must match (InputError).
std::vector<double> AbsoluteTranslationErrors(std::span<const Rigid3> estimate,
                                              std::span<const Rigid3> reference);

// RPE over `delta` frames: E_i = (ref_i⁻¹ ref_{i+δ})⁻¹ (est_i⁻¹ est_{i+δ}); its translation
// norm [m] and rotation angle [deg] per pair (#frames − δ entries each).
struct RelativeErrors {
  std::vector<double> translation;
  std::vector<double> rotation_deg;
};
RelativeErrors RelativePoseErrors(std::span<const Rigid3> estimate,
                                  std::span<const Rigid3> reference, int delta = 1);

}  // namespace mmh::metrics
