#include "people/self_appraisal.h"

#include "core/error.h"

namespace mmh::people {

void SelfAppraisalOptions::Validate(const std::string& prefix) const {
  // Both biases flatter the animator's own later work; negative values would model the opposite
  // bias, which no source suggests.
  RequireFinite(progress_weight, prefix + ".progress_weight");
  RequireNonNegative(progress_weight, prefix + ".progress_weight");
  RequireFinite(choice_bonus, prefix + ".choice_bonus");
  RequireNonNegative(choice_bonus, prefix + ".choice_bonus");
}

double SelfAppraisalBias(const SelfAppraisalOptions& options, int item, int takes) {
  if (takes < 1 || item < 0 || item > takes) {
    ThrowBadValue("self-appraised item", std::to_string(item),
                  "a take 0.." + std::to_string(takes - 1) + " or the montage (" +
                      std::to_string(takes) + ")");
  }
  if (item == takes) return options.progress_weight + options.choice_bonus;
  const double progress = takes > 1 ? static_cast<double>(item) / (takes - 1) : 1.0;
  return options.progress_weight * progress;
}

}  // namespace mmh::people
