// The files of an animator's run (`mmh run --out DIR`), each written atomically:
//   takes/take_K/ (practice/ for the practice take):
//     truth.tum, tracked.tum     table_T_proxy per frame (ground truth; tracker, gaps filled)
//     status.csv                 frame,timestamp,status (tracked / predicted / lost)
//     truth_annotation.csv       the slider block's true values (timestamp,value)
//     read_annotation.csv        the slider reader's values
//     quality.csv                frame,timestamp,beat,quality,judgement (the latent ground truth)
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

// Montages, metrics and tidy tables (the takes are written by WriteTakeRun).
void WriteAnimatorRun(const std::filesystem::path& out, const AnimatorRun& run);

// The tidy metrics table of a metrics.json.
std::string MetricsToCsv(const nlohmann::json& metrics);

}  // namespace mmh::pipeline
