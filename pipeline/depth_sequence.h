// The first frames of a real recording as a depth sequence for `mmh sensor-check`'s temporal
// structure (sim/sensor_check_run.h). Here, not in sim/ or track/: it reads with the tracker's
// recording readers (BOP, YCB-Video, TUM with camera.json; intrinsics and depth scale from the
// dataset) and hands the sensor model's check plain depth.
#pragma once

#include <filesystem>

#include "sim/sensor_check_run.h"

namespace mmh::pipeline {

// The first `frames` frames of the recording in `folder` (track::RecordingFrameSource; a TUM RGB-D
// folder, with depth.txt, through RgbdFolderReader), depth in metres; frames < 1: as many as it
// has, at most -frames. InputError naming the folder when it
// has fewer frames (none) or they differ in size.
sim::DepthSequence ReadDepthSequence(const std::filesystem::path& folder, int frames);

// A real frame and the same view rendered (sim::RealView): the first frame of the recording in
// `folder`, the object's pixels where `label` (an 8-bit label image of that frame, YCB-Video's
// -label.png) holds `object`, and the view's render config from `view` (render_real_view.py's
// output without paths) with `model` as the proxy and `trajectory` as its poses, rendered by
// `sensor` (the sensor under test: the view file places things, it does not choose the sensor).
// The view's scene.objects name their mesh files relative to the view file (as any config file).
// `frames` > 1: the recording's next frames too (RealView::later_frames; frames <= -1: as many as
// the recording has, at most -frames), their labels named as
// `label` with its leading frame number counted up (YCB-Video's 000001-label.png, 000002-...);
// InputError naming the label file when its name has no leading number.
// InputError naming the file when the label image differs in size or holds no pixel of the
// object, or when the view file has a sensor section.
sim::RealView ReadRealView(const std::filesystem::path& folder, const std::filesystem::path& label,
                           int object, const std::filesystem::path& view,
                           const std::filesystem::path& model,
                           const std::filesystem::path& trajectory,
                           const sim::KinectSensorOptions& sensor, int frames = 1);

}  // namespace mmh::pipeline
