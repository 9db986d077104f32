// The metrics of one animator's run (metrics.json): tracking against the ground truth (errors,
// ADD/ADD-S, success, losses and recovery, evo's APE/RPE), annotation reading (RMSE, lag,
// clipping), and the montage (costs, the Segment Length Constraint's cost, liked frames used and
// disliked frames avoided, segments, seam jumps against the takes' own, latent quality against the
// takes', and how much the montage from tracked data differs from the one from the ground truth).
// docs/pipeline.md defines every entry.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/triangle_mesh.h"

namespace mmh::pipeline {

struct RunConfig;
struct AnimatorRun;

// `proxy_model` and `practice_model` (when the run has a practice take) are the models the
// sessions rendered (for ADD/ADD-S).
nlohmann::json ComputeRunMetrics(const RunConfig& config, const AnimatorRun& run,
                                 const TriangleMesh& proxy_model,
                                 const TriangleMesh* practice_model);

// Time per stage [s] and frames per second (metrics.json "seconds").
nlohmann::json SecondsToJson(const AnimatorRun& run);

// The same as a tidy CSV: stage,seconds,frames,frames_per_second (frames: those the stage
// rendered and tracked or read).
std::string TimingsToCsv(const AnimatorRun& run);

// metrics.json flattened to "a.b.c" keys (arrays indexed: "takes.0.tracking.success_rate"), in
// key order; the tidy metrics.csv and `mmh regress` read it.
std::vector<std::pair<std::string, double>> FlattenMetrics(const nlohmann::json& metrics);

}  // namespace mmh::pipeline
