// The first frames of a real recording as a depth sequence for `mmh sensor-check`'s temporal
// structure (sim/sensor_check_run.h). Here, not in sim/ or track/: it reads with the tracker's
// recording readers (BOP, YCB-Video, TUM with camera.json; intrinsics and depth scale from the
// dataset) and hands the sensor model's check plain depth.
#pragma once

#include <filesystem>

#include "sim/sensor_check_run.h"

namespace mmh::pipeline {

// The first `frames` frames of the recording in `folder` (track::RecordingFrameSource), depth in
// metres. InputError naming the folder when it has fewer frames or they differ in size.
sim::DepthSequence ReadDepthSequence(const std::filesystem::path& folder, int frames);

}  // namespace mmh::pipeline
