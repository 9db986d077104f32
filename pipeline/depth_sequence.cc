#include "pipeline/depth_sequence.h"

#include <algorithm>
#include <cctype>
#include <nlohmann/json.hpp>
#include <string>

#include "core/config.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/rgbd_folder.h"
#include "core/rgbd_frame.h"
#include "track/recording.h"

namespace mmh::pipeline {

namespace {

// The frames' depth in metres into `sequence`, checking that every frame has the first's size.
void AddDepth(const std::filesystem::path& folder, int k, const RgbdFrame& frame,
              sim::DepthSequence& sequence) {
  if (k == 0) {
    sequence.intrinsics = frame.depth_intrinsics;
    sequence.width = frame.depth_intrinsics.width;
    sequence.height = frame.depth_intrinsics.height;
  } else if (frame.depth_intrinsics.width != sequence.width ||
             frame.depth_intrinsics.height != sequence.height) {
    ThrowBadValue(folder.string() + ": frame " + std::to_string(k) + " size",
                  std::to_string(frame.depth_intrinsics.width) + "x" +
                      std::to_string(frame.depth_intrinsics.height),
                  "the first frame's " + std::to_string(sequence.width) + "x" +
                      std::to_string(sequence.height));
  }
  std::vector<float> depth_m(frame.depth.size());
  for (size_t i = 0; i < depth_m.size(); ++i) {
    depth_m[i] = static_cast<float>(frame.depth[i] * frame.depth_scale);
  }
  sequence.depth_m.push_back(std::move(depth_m));
}

void CheckFrameCount(const std::filesystem::path& folder, int available, int& frames) {
  if (frames < 1) frames = std::min(-frames, available);
  if (available < frames || frames < 1) {
    ThrowBadValue(folder.string() + ": frames", std::to_string(available),
                  "at least " + std::to_string(std::max(frames, 1)) + " frames");
  }
}

}  // namespace

sim::DepthSequence ReadDepthSequence(const std::filesystem::path& folder, int frames) {
  if (!std::filesystem::is_directory(folder)) {
    ThrowBadValue(folder.string(), "no such folder",
                  "a BOP scene, a YCB-Video folder or a TUM RGB-D folder (depth.txt)");
  }
  sim::DepthSequence sequence;
  // A TUM RGB-D folder (depth.txt; its intrinsics from camera.json or the freiburg name).
  if (std::filesystem::exists(folder / "depth.txt")) {
    const RgbdFolderReader reader(folder);
    sequence.name = "real TUM " + folder.filename().string();
    CheckFrameCount(folder, reader.size(), frames);
    for (int k = 0; k < frames; ++k) AddDepth(folder, k, reader.Read(k), sequence);
    return sequence;
  }
  // RecordingFrameSource's own message names only the layouts it reads.
  if (!track::DetectRecordingLayout(folder)) {
    ThrowBadValue(folder.string(), "a folder of no known layout",
                  "a TUM RGB-D folder (depth.txt), a BOP scene (scene_camera.json, "
                  "scene_gt.json) or a YCB-Video folder (NNNNNN-depth.png with NNNNNN-meta.mat)");
  }
  track::RecordingFrameSource source(folder);
  sequence.name = std::string("real ") + track::RecordingLayoutName(source.layout()) + " " +
                  folder.filename().string();
  CheckFrameCount(folder, source.size(), frames);
  RgbdFrame frame;
  for (int k = 0; k < frames && source.Next(&frame); ++k) AddDepth(folder, k, frame, sequence);
  return sequence;
}

namespace {

// The label image of the frame `later` frames after `first_label`'s: the leading number of its
// name counted up, zero-padded to the same width (YCB-Video: 000001-label.png, 000002-...).
std::filesystem::path LaterLabel(const std::filesystem::path& first_label, int later) {
  const std::string name = first_label.filename().string();
  size_t digits = 0;
  while (digits < name.size() && std::isdigit(static_cast<unsigned char>(name[digits]))) ++digits;
  if (digits == 0 || digits > 9) {
    ThrowBadValue(first_label.string() + ": name", "\"" + name + "\"",
                  "a name starting with its frame's number (YCB-Video's 000001-label.png), to "
                  "find the later frames' labels");
  }
  std::string number = std::to_string(std::stol(name.substr(0, digits)) + later);
  if (number.size() < digits) number.insert(0, digits - number.size(), '0');
  return first_label.parent_path() / (number + name.substr(digits));
}

// The object's pixels (`mask`) and the other labelled objects' (`others`) in an 8-bit label
// image of the depth frame's size.
void ReadLabels(const std::filesystem::path& label, int object, int width, int height,
                std::vector<uint8_t>* mask, std::vector<uint8_t>* others) {
  const RgbImage labels = ReadRgbImage(label);
  if (labels.width != width || labels.height != height) {
    ThrowBadValue(label.string() + ": size",
                  std::to_string(labels.width) + "x" + std::to_string(labels.height),
                  "the depth frame's " + std::to_string(width) + "x" + std::to_string(height));
  }
  const size_t n = static_cast<size_t>(width) * height;
  mask->assign(n, 0);
  others->assign(n, 0);
  size_t pixels = 0;
  for (size_t p = 0; p < n; ++p) {
    (*mask)[p] = labels.rgb[3 * p] == object;
    (*others)[p] = labels.rgb[3 * p] != 0 && labels.rgb[3 * p] != object;
    pixels += (*mask)[p];
  }
  if (pixels == 0) {
    ThrowBadValue(label.string() + ": object", std::to_string(object), "a label the image holds");
  }
}

}  // namespace

sim::RealView ReadRealView(const std::filesystem::path& folder, const std::filesystem::path& label,
                           int object, const std::filesystem::path& view,
                           const std::filesystem::path& model,
                           const std::filesystem::path& trajectory,
                           const sim::KinectSensorOptions& sensor, int frames) {
  sim::DepthSequence sequence = ReadDepthSequence(folder, frames);
  frames = static_cast<int>(sequence.depth_m.size());
  sim::RealView real;
  real.name = sequence.name + " frame 1";
  real.width = sequence.width;
  real.height = sequence.height;
  real.intrinsics = sequence.intrinsics;
  real.depth_m = std::move(sequence.depth_m.front());
  ReadLabels(label, object, real.width, real.height, &real.mask, &real.others);
  for (int k = 1; k < frames; ++k) {
    sim::RealView::Frame frame;
    frame.depth_m = std::move(sequence.depth_m[k]);
    ReadLabels(LaterLabel(label, k), object, real.width, real.height, &frame.mask, &frame.others);
    real.later_frames.push_back(std::move(frame));
  }
  Config config = Config::Load(view);
  if (config.root().contains("sensor")) {
    ThrowBadValue(view.string() + ": sensor", "a sensor section",
                  "none (the view is rendered by the sensor under test: --config and --set)");
  }
  config.Set("render.proxy=" + nlohmann::json(model.string()).dump());
  config.Set("render.trajectory=" + nlohmann::json(trajectory.string()).dump());
  real.config = sim::RenderConfig::FromConfig(config);
  real.config.sensor = sensor;
  return real;
}

}  // namespace mmh::pipeline
