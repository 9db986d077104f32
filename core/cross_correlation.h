// The lag between a signal and a delayed copy of it, by cross-correlation: the annotator's reaction
// delay (people/annotator.h) and the lag of a read annotation (metrics/annotation_metrics.h).
#pragma once

#include <span>

namespace mmh {

// The lag [frames] in [0, max_lag] that maximises the Pearson correlation between `reference` and
// the `delayed` copy of it (delayed(t) ≈ reference(t − lag)) over their common range; a parabola
// through the peak and its neighbours gives a fraction. InputError when the signals are not
// longer than max_lag + 2 samples.
double CrossCorrelationLag(std::span<const double> reference, std::span<const double> delayed,
                           int max_lag);

}  // namespace mmh
