// The step law of the missing bands beside depth edges: how wide a depth sensor's holes beside a
// depth step are, against the step. It measures a sensor's geometry from its depth images alone,
// whatever the scene.
//
// A projector at distance B along +x of the camera that delivers the image (the IR camera for raw
// frames, the colour camera for frames registered to it) casts a shadow on the far surface beyond
// a near edge. Along an image row the shadow runs from the near surface's edge to where the
// projector's ray past the edge meets the far surface:
//     w = f_x B (1 / z_near - 1 / z_far) = B x,   x = f_x (1 / z_near - 1 / z_far)  [px / m],
// whatever the edge's slant in the image (the baseline lies along the rows). On the edge's other
// side the camera that delivers the image sees far surface that the IR camera, a distance B' the
// other way, does not: a run of the same form with B'. A block matcher adds the windows that
// fail beside either (a constant part, independent of the step). So each side's runs follow
//     run = B x + c,
// and the fit gives B (metres: the geometry) and c (pixels: the matcher).
//
// Runs are ClassifyMissing's shadow runs (far side on the left) and edge runs (far side on the
// right), whose valid neighbours give z_far and z_near. Runs with x < min_step_px_per_m are left
// out: beside a small step the window's failures are the whole run. A sensor's runs need not
// follow one line over all steps (a matcher may fill part of a wide shadow, or lose a constant
// beside a narrow one): fit ranges of steps apart (max_step_px_per_m) and compare like ranges. The
// fit is least absolute deviations (the runs' errors are not Gaussian: a hole beside a shadow
// lengthens it, a third surface ends it early); its slope's confidence interval is the percentile
// bootstrap over runs.
#pragma once

#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "sim/error_structure.h"

namespace mmh::sim {

// One missing run beside a depth step.
struct StepRun {
  double step_px_per_m = 0;  // x = f_x (1 / z_near - 1 / z_far)
  double length_px = 0;      // along its row
};

struct StepLawOptions {
  // Runs beside steps with x outside [min, max] are left out (40 px / m: 2 px of shadow at 5 cm;
  // max: a range of steps on its own, e.g. the small ones, whose runs may follow another line).
  double min_step_px_per_m = 40.0;
  double max_step_px_per_m = std::numeric_limits<double>::infinity();
  int min_runs = 10;  // fewer: no fit (NaN)
  // Bootstrap resamples for the slope's interval (0: none, the interval is NaN).
  int bootstrap_samples = 200;
  double confidence = 0.95;
  uint64_t seed = 1;  // of the resampling (the same seed, the same interval)

  void Validate(const std::string& prefix) const;
};

struct StepLaw {
  int runs = 0;             // fitted (after min_step_px_per_m)
  double slope_m = 0;       // B (NaN: no fit)
  double intercept_px = 0;  // c (NaN: no fit)
  double slope_low_m = 0;   // the slope's bootstrap interval (NaN: none)
  double slope_high_m = 0;
  // The 10th and 90th percentiles of the fitted runs' x (NaN: no run): the slope is only as
  // good as the spread of the steps (a scene of small steps alone confounds it with c).
  double step_p10_px_per_m = 0, step_p90_px_per_m = 0;
};

// The shadow runs (`shadow`) and edge runs (`edge`) of a depth image (width x height row-major
// [m], 0 = missing; fx_px the focal length of the camera that delivers it), appended; either may
// be nullptr.
void CollectStepRuns(const std::vector<float>& depth_m, int width, int height, double fx_px,
                     std::vector<StepRun>* shadow, std::vector<StepRun>* edge,
                     const ErrorStructureOptions& options = {});

// The least-absolute-deviations line run = slope x + intercept through `runs` (those with x in
// [min_step_px_per_m, max_step_px_per_m]), with the slope's bootstrap interval. Runs from several
// frames of one sensor may be pooled when their focal lengths are the same (else scale the
// lengths).
StepLaw FitStepLaw(std::span<const StepRun> runs, const StepLawOptions& options = {});

// The sum of |length - slope x - intercept| over `runs`: the objective FitStepLaw minimises.
double AbsoluteDeviation(std::span<const StepRun> runs, double slope_m, double intercept_px);

nlohmann::json ToJson(const StepLaw& law);

}  // namespace mmh::sim
