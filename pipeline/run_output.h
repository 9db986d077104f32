// The files of an animator's run (`mmh run --out DIR`), each written atomically:
//   takes/take_K/ (practice/ for the practice take):
//     truth.tum, tracked.tum     table_T_proxy per frame (ground truth; tracker, gaps filled)
//     status.csv                 frame,timestamp,status (tracked / predicted / lost)[,slider_found]
//     truth_annotation.csv       the slider block's true values (timestamp,value)
//     read_annotation.csv        the slider reader's values
//     quality.csv                frame,timestamp,beat,quality,judgement (the latent ground truth)
//     session.json               frames, camera_T_table (true and estimated); written last
//   montage/, montage_truth/     montage.tum, segments.csv, timeline.csv, summary.json
//   metrics.json                 pipeline/run_metrics.h
//   metrics.csv                  tidy: scope,take,metric,value (metrics.json flattened)
//   tracking_frames.csv          tidy: take,frame,status,rotation_deg,translation_m
//   seams.csv                    tidy: montage,seam,frame,from_take,to_take,position_jump_m,...
#pragma once

#include <filesystem>

#include "pipeline/animator_run.h"

namespace mmh::pipeline {

// The folder of one take (as TakeDone reports it).
void WriteTakeRun(const std::filesystem::path& out, const TakeRun& take, bool practice);

// Reads back the session results WriteTakeRun wrote for `take` (whose performance, truth and
// truth_annotation are set): tracked poses, status, slider_found, read annotation, camera poses.
// Returns false when the take's folder is not complete (no session.json: the take did not
// finish); InputError naming the file when its contents do not belong to this take (frame count,
// ground truth, malformed rows).
bool LoadTakeRun(const std::filesystem::path& out, TakeRun& take, bool practice);

// Montages, metrics and tidy tables (the takes are written by WriteTakeRun); run.metrics must be
// set (run.metrics true). `full_fidelity`: the takes were rendered and tracked (now or in the
// run resumed), so every frame is measured against its truth into tracking_errors.csv.
void WriteAnimatorRun(const std::filesystem::path& out, const AnimatorRun& run,
                      bool full_fidelity);

// The tidy metrics table of a metrics.json.
std::string MetricsToCsv(const nlohmann::json& metrics);

}  // namespace mmh::pipeline
