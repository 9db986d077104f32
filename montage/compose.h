// The MotionMontage compositor (paper, "Compositing the takes into the montage"): reaction shift,
// DTW of every take to the reference, annotation warp (eq. 6), data and smoothness costs (eqs. 8,
// 9), the exact constrained labelling (eqs. 7-12), unwarp and blend.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "core/annotation.h"
#include "core/trajectory.h"
#include "montage/annotation_warp.h"
#include "montage/blend.h"
#include "montage/dtw.h"
#include "montage/labelling.h"
#include "montage/smoothness.h"

namespace mmh::montage {

struct ComposeOptions {
  // Reaction time [s]: recorded annotations are shifted back by this much (paper: 0.3 s, the
  // average human reaction time plus block movement).
  double reaction_time = 0.3;
  // Index of the reference take (paper: the first take).
  int reference_take = 0;
  // Time-warp the takes onto the reference (true) or use them as they are (false: the layered
  // mode of "Creating montages for more than one object", where all takes have equal length).
  bool time_warp = true;
  // Form of eq. 6; see AnnotationWarpForm.
  AnnotationWarpForm annotation_warp = AnnotationWarpForm::kConserving;
  DtwOptions dtw;
  SmoothnessOptions smoothness;
  LabellingOptions labelling;
  BlendOptions blend;

  template <class V>
  void VisitFields(V& v) {
    v("reaction_time", reaction_time);
    v("reference_take", reference_take);
    v("time_warp", time_warp);
    v("annotation_warp", annotation_warp);
    v("dtw", dtw);
    v("smoothness", smoothness);
    v("labelling", labelling);
    v("blend", blend);
  }
  void Validate(const std::string& prefix) const;
};

struct StageTimings {
  double validate = 0.0;  // input checks [s]
  double dtw = 0.0;       // all warps [s]
  double annotations = 0.0;
  double smoothness = 0.0;
  double labelling = 0.0;  // constrained and unconstrained solves
  double blend = 0.0;      // unwarp and blend
  double total = 0.0;
};

struct ComposeSummary {
  // C_T of eq. 7 of the chosen (constrained) labelling and its two terms.
  double total_cost = 0.0;
  double data_cost = 0.0;
  double smoothness_cost = 0.0;
  // C_T of the optimum without the Segment Length Constraint (d = 0), and the constraint's
  // relative increase in % (100 (C - C0) / |C0|; 0 when C0 = 0).
  double unconstrained_cost = 0.0;
  double constraint_increase_percent = 0.0;
  // Segments of the optimum without the constraint that are not longer than d ("quick
  // transitions"), and the number of its segments.
  int unconstrained_short_segments = 0;
  int unconstrained_segments = 0;
  // The shortest segment of the montage, in reference frames and in montage frames.
  int shortest_segment_reference = 0;
  int shortest_segment_montage = 0;
  // Montage length in frames, reference length, number of takes, reaction shift in frames.
  int montage_frames = 0;
  int reference_frames = 0;
  int takes = 0;
  int reaction_shift_frames = 0;
  // DTW cost of each take's warp (0 for the reference).
  std::vector<double> dtw_costs;
  // Share of DTW cells evaluated (pruning), over all non-reference takes.
  double dtw_cells_evaluated_share = 0.0;
  std::vector<std::string> warnings;
  StageTimings seconds;
};

struct Montage {
  Trajectory trajectory;
  std::vector<MontageSegment> segments;
  // Take chosen for each reference frame (n entries).
  std::vector<int> labels;
  // Warp of each take onto the reference (n entries each; the identity for the reference).
  std::vector<std::vector<int>> warps;
  // Reaction-shifted, warped annotation of each take on the reference timeline (n entries each).
  std::vector<std::vector<double>> warped_annotations;
  ComposeSummary summary;
};

// Validates every take and annotation (InputError naming "take i" / "annotation i", or the file
// names given in `names`), then composes. Needs at least two takes; each take needs an annotation
// of the same length; every take must be longer than d unless d = 0.
Montage Compose(const std::vector<Trajectory>& takes, const std::vector<Annotation>& annotations,
                const ComposeOptions& options, const std::vector<std::string>& names = {});

// The summary as JSON (for summary.json) and the segments as a tidy CSV.
nlohmann::json SummaryToJson(const ComposeSummary& summary,
                             const std::vector<MontageSegment>& segments);
std::string SegmentsToCsv(const std::vector<MontageSegment>& segments);
// Per reference frame: the chosen take, each take's warp and warped annotation (tidy CSV).
std::string TimelineToCsv(const Montage& montage);

}  // namespace mmh::montage
