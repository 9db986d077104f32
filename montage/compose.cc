#include "montage/compose.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>

#include "core/error.h"
#include "core/options.h"

namespace mmh::montage {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string NameOf(const std::vector<std::string>& names, std::size_t i, const char* kind) {
  if (i < names.size() && !names[i].empty()) return names[i];
  return std::string(kind) + " " + std::to_string(i);
}

void ValidateInputs(const std::vector<Trajectory>& takes,
                    const std::vector<Annotation>& annotations, const ComposeOptions& options,
                    const std::vector<std::string>& names) {
  const int m = static_cast<int>(takes.size());
  if (m < 2) {
    ThrowBadValue("takes", std::to_string(m) + (m == 1 ? " take" : " takes"),
                  "at least 2 takes to composite (one take is already its own montage)");
  }
  if (annotations.size() != takes.size()) {
    ThrowBadValue(
        "annotations",
        std::to_string(annotations.size()) + " annotations for " + std::to_string(m) + " takes",
        "one annotation per take, in the same order");
  }
  if (options.reference_take >= m) {
    ThrowBadValue("montage.reference_take", std::to_string(options.reference_take),
                  "a take index in [0, " + std::to_string(m - 1) + "]");
  }
  const int d = options.labelling.min_segment_length;
  for (int i = 0; i < m; ++i) {
    const std::string take_name = NameOf(names, i, "take");
    const std::string annotation_name = NameOf(names, m + i, "annotation");
    ValidateTrajectory(takes[i], take_name);
    ValidateAnnotation(annotations[i], annotation_name);
    if (takes[i].empty()) ThrowBadValue(take_name, "no frames", "a take with frames");
    if (annotations[i].size() != takes[i].size()) {
      ThrowBadValue(annotation_name, std::to_string(annotations[i].size()) + " rows",
                    std::to_string(takes[i].size()) + " rows, one per frame of " + take_name);
    }
    // The annotation is per frame of its take (DESIGN.md, "File formats"): its timestamps must be
    // the take's, within a quarter frame (an annotation in milliseconds, or of another take, or
    // shifted by seconds, would otherwise be used silently).
    const double period = MedianFramePeriod(takes[i].timestamps);
    const double tolerance = period > 0 ? 0.25 * period : 1e-3;
    for (std::size_t k = 0; k < takes[i].size(); ++k) {
      const double a = annotations[i].timestamps[k], t = takes[i].timestamps[k];
      if (!(std::abs(a - t) <= tolerance)) {
        ThrowBadValue(
            annotation_name + ", row " + std::to_string(k + 1) + ", timestamp", FormatNumber(a),
            "the timestamp of frame " + std::to_string(k) + " of " + take_name + ", " +
                FormatNumber(t) + " s (within a quarter frame, " + FormatNumber(tolerance) + " s)");
      }
    }
    if (d > 0 && static_cast<int>(takes[i].size()) <= d) {
      ThrowBadValue(take_name, std::to_string(takes[i].size()) + " frames",
                    "more than montage.labelling.min_segment_length = " + std::to_string(d) +
                        " frames (the shortest segment a montage may take)");
    }
    if (!options.time_warp && takes[i].size() != takes[0].size()) {
      ThrowBadValue(take_name, std::to_string(takes[i].size()) + " frames",
                    std::to_string(takes[0].size()) + " frames like " + NameOf(names, 0, "take") +
                        " (montage.time_warp = false needs equal-length takes)");
    }
  }
}

}  // namespace

void ComposeOptions::Validate(const std::string& prefix) const {
  if (!std::isfinite(reaction_time) || reaction_time < 0 || reaction_time > 5) {
    ThrowBadValue(prefix + ".reaction_time", FormatNumber(reaction_time), "seconds in [0, 5]");
  }
  if (reference_take < 0) {
    ThrowBadValue(prefix + ".reference_take", std::to_string(reference_take), "an index >= 0");
  }
  dtw.Validate(prefix + ".dtw");
  smoothness.Validate(prefix + ".smoothness");
  labelling.Validate(prefix + ".labelling");
  blend.Validate(prefix + ".blend");
}

Montage Compose(const std::vector<Trajectory>& takes, const std::vector<Annotation>& annotations,
                const ComposeOptions& options, const std::vector<std::string>& names) {
  const auto start = Clock::now();
  options.Validate("montage");
  ValidateInputs(takes, annotations, options, names);
  Montage montage;
  ComposeSummary& summary = montage.summary;
  const int m = static_cast<int>(takes.size());
  const int r = options.reference_take;
  const Trajectory& reference = takes[r];
  const int n = static_cast<int>(reference.size());
  summary.takes = m;
  summary.reference_frames = n;
  summary.seconds.validate = SecondsSince(start);

  // 1. Warps of every take onto the reference (eqs. 1-5), one task per take.
  auto stage = Clock::now();
  montage.warps.assign(m, {});
  summary.dtw_costs.assign(m, 0.0);
  std::vector<DtwSummary> dtw_summaries(m);
  tbb::parallel_for(0, m, [&](int l) {
    if (l == r || !options.time_warp) {
      montage.warps[l].resize(takes[l].size());
      std::iota(montage.warps[l].begin(), montage.warps[l].end(), 0);
      return;
    }
    DtwResult result = ComputeDtw(reference, takes[l], options.dtw);
    montage.warps[l] = std::move(result.warp);
    dtw_summaries[l] = result.summary;
  });
  std::int64_t evaluated = 0, total = 0;
  for (int l = 0; l < m; ++l) {
    summary.dtw_costs[l] = dtw_summaries[l].cost;
    evaluated += dtw_summaries[l].cells_evaluated;
    total += dtw_summaries[l].cells_total;
  }
  summary.dtw_cells_evaluated_share = total > 0 ? static_cast<double>(evaluated) / total : 0.0;
  summary.seconds.dtw = SecondsSince(stage);

  // 2. Reaction shift, then eq. 6 onto the reference timeline; data cost of eq. 8.
  stage = Clock::now();
  const double frame_period = MedianFramePeriod(reference.timestamps);
  summary.reaction_shift_frames = ReactionShiftFrames(options.reaction_time, frame_period);
  LabellingProblem problem;
  problem.frames = n;
  problem.takes = m;
  problem.data.resize(static_cast<std::size_t>(n) * m);
  montage.warped_annotations.resize(m);
  for (int l = 0; l < m; ++l) {
    const int shift =
        ReactionShiftFrames(options.reaction_time, MedianFramePeriod(takes[l].timestamps));
    const auto shifted = ShiftForReaction(annotations[l].values, shift);
    montage.warped_annotations[l] =
        WarpAnnotation(shifted, montage.warps[l], options.annotation_warp);
    for (int t = 0; t < n; ++t) {
      problem.data[static_cast<std::size_t>(t) * m + l] = -montage.warped_annotations[l][t];
    }
  }
  summary.seconds.annotations = SecondsSince(stage);

  // 3. Smoothness cost of eq. 9.
  stage = Clock::now();
  problem.transitions = ComputeSmoothnessCosts(takes, montage.warps, options.smoothness);
  summary.seconds.smoothness = SecondsSince(stage);

  // 4. The constrained optimum (eqs. 11-12) and, for the report, the unconstrained one (eq. 10).
  stage = Clock::now();
  LabellingOptions unconstrained_options = options.labelling;
  unconstrained_options.min_segment_length = 0;
  LabellingResult constrained, unconstrained;
  tbb::parallel_invoke([&] { constrained = SolveLabelling(problem, options.labelling); },
                       [&] { unconstrained = SolveLabelling(problem, unconstrained_options); });
  summary.seconds.labelling = SecondsSince(stage);
  montage.labels = constrained.labels;
  summary.total_cost = constrained.total_cost;
  summary.data_cost = constrained.data_cost;
  summary.smoothness_cost = constrained.smoothness_cost;
  summary.unconstrained_cost = unconstrained.total_cost;
  summary.constraint_increase_percent =
      unconstrained.total_cost != 0.0
          ? 100.0 * (constrained.total_cost - unconstrained.total_cost) /
                std::abs(unconstrained.total_cost)
          : 0.0;
  const int d = options.labelling.min_segment_length;
  for (const auto& s : SegmentsOf(unconstrained.labels)) {
    ++summary.unconstrained_segments;
    if (s.length() <= d) ++summary.unconstrained_short_segments;
  }
  if (!constrained.feasible) {
    summary.warnings.push_back("no labelling has every segment longer than " + std::to_string(d) +
                               " frames (reference has " + std::to_string(n) +
                               "); the montage is the single take of least cost");
  }

  // 5. Unwarp to the takes' own speeds and blend across the transitions.
  stage = Clock::now();
  montage.segments = Unwarp(montage.labels, montage.warps);
  int narrowed = 0;
  montage.trajectory = BlendMontage(takes, montage.segments, options.blend,
                                    reference.timestamps.front(), frame_period, &narrowed);
  if (narrowed > 0) {
    summary.warnings.push_back(std::to_string(narrowed) +
                               " transition(s) blended over a narrower window than " +
                               std::to_string(options.blend.window) +
                               " frames: a neighbouring segment plays fewer source frames");
  }
  summary.seconds.blend = SecondsSince(stage);

  summary.montage_frames = static_cast<int>(montage.trajectory.size());
  summary.shortest_segment_reference = n;
  summary.shortest_segment_montage = summary.montage_frames;
  for (const auto& s : montage.segments) {
    summary.shortest_segment_reference =
        std::min(summary.shortest_segment_reference, s.reference_last - s.reference_first + 1);
    summary.shortest_segment_montage =
        std::min(summary.shortest_segment_montage, s.montage_last - s.montage_first + 1);
  }
  summary.seconds.total = SecondsSince(start);
  return montage;
}

nlohmann::json SummaryToJson(const ComposeSummary& summary,
                             const std::vector<MontageSegment>& segments) {
  nlohmann::json j;
  j["total_cost"] = summary.total_cost;
  j["data_cost"] = summary.data_cost;
  j["smoothness_cost"] = summary.smoothness_cost;
  j["unconstrained_cost"] = summary.unconstrained_cost;
  j["constraint_increase_percent"] = summary.constraint_increase_percent;
  j["unconstrained_segments"] = summary.unconstrained_segments;
  j["unconstrained_short_segments"] = summary.unconstrained_short_segments;
  j["segments"] = segments.size();
  j["shortest_segment_reference_frames"] = summary.shortest_segment_reference;
  j["shortest_segment_montage_frames"] = summary.shortest_segment_montage;
  j["montage_frames"] = summary.montage_frames;
  j["reference_frames"] = summary.reference_frames;
  j["takes"] = summary.takes;
  j["reaction_shift_frames"] = summary.reaction_shift_frames;
  j["dtw_costs"] = summary.dtw_costs;
  j["dtw_cells_evaluated_share"] = summary.dtw_cells_evaluated_share;
  j["warnings"] = summary.warnings;
  nlohmann::json seconds;
  seconds["validate"] = summary.seconds.validate;
  seconds["dtw"] = summary.seconds.dtw;
  seconds["annotations"] = summary.seconds.annotations;
  seconds["smoothness"] = summary.seconds.smoothness;
  seconds["labelling"] = summary.seconds.labelling;
  seconds["blend"] = summary.seconds.blend;
  seconds["total"] = summary.seconds.total;
  j["seconds"] = seconds;
  return j;
}

std::string SegmentsToCsv(const std::vector<MontageSegment>& segments) {
  std::ostringstream out;
  out << "segment,take,reference_first,reference_last,source_first,source_last,montage_first,"
         "montage_last,reference_frames,montage_frames\n";
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const auto& s = segments[i];
    out << i << ',' << s.take << ',' << s.reference_first << ',' << s.reference_last << ','
        << s.source_first << ',' << s.source_last << ',' << s.montage_first << ',' << s.montage_last
        << ',' << (s.reference_last - s.reference_first + 1) << ','
        << (s.montage_last - s.montage_first + 1) << '\n';
  }
  return out.str();
}

std::string TimelineToCsv(const Montage& montage) {
  std::ostringstream out;
  out << "reference_frame,take";
  const std::size_t m = montage.warped_annotations.size();
  for (std::size_t l = 0; l < m; ++l) out << ",warp_" << l;
  for (std::size_t l = 0; l < m; ++l) out << ",warped_annotation_" << l;
  out << '\n';
  for (std::size_t t = 0; t < montage.labels.size(); ++t) {
    out << t << ',' << montage.labels[t];
    for (std::size_t l = 0; l < m; ++l) out << ',' << montage.warps[l][t];
    for (std::size_t l = 0; l < m; ++l)
      out << ',' << FormatNumber(montage.warped_annotations[l][t]);
    out << '\n';
  }
  return out.str();
}

}  // namespace mmh::montage
