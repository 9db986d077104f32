#include "pipeline/depth_sequence.h"

#include <nlohmann/json.hpp>
#include <string>

#include "core/config.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/rgbd_frame.h"
#include "track/recording.h"

namespace mmh::pipeline {

sim::DepthSequence ReadDepthSequence(const std::filesystem::path& folder, int frames) {
  track::RecordingFrameSource source(folder);
  sim::DepthSequence sequence;
  sequence.name = std::string("real ") + track::RecordingLayoutName(source.layout()) + " " +
                  folder.filename().string();
  if (source.size() < frames) {
    ThrowBadValue(folder.string() + ": frames", std::to_string(source.size()),
                  "at least " + std::to_string(frames) + " frames (sensor-check's temporal lags)");
  }
  RgbdFrame frame;
  for (int k = 0; k < frames && source.Next(&frame); ++k) {
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
  return sequence;
}

sim::RealView ReadRealView(const std::filesystem::path& folder, const std::filesystem::path& label,
                           int object, const std::filesystem::path& view,
                           const std::filesystem::path& model,
                           const std::filesystem::path& trajectory,
                           const sim::KinectSensorOptions& sensor) {
  sim::DepthSequence first = ReadDepthSequence(folder, 1);
  sim::RealView real;
  real.name = first.name + " frame 1";
  real.width = first.width;
  real.height = first.height;
  real.intrinsics = first.intrinsics;
  real.depth_m = std::move(first.depth_m.front());
  const RgbImage labels = ReadRgbImage(label);
  if (labels.width != real.width || labels.height != real.height) {
    ThrowBadValue(label.string() + ": size",
                  std::to_string(labels.width) + "x" + std::to_string(labels.height),
                  "the depth frame's " + std::to_string(real.width) + "x" +
                      std::to_string(real.height));
  }
  real.mask.assign(real.depth_m.size(), 0);
  real.others.assign(real.depth_m.size(), 0);
  size_t pixels = 0;
  for (size_t p = 0; p < real.mask.size(); ++p) {
    real.mask[p] = labels.rgb[3 * p] == object;
    real.others[p] = labels.rgb[3 * p] != 0 && labels.rgb[3 * p] != object;
    pixels += real.mask[p];
  }
  if (pixels == 0) {
    ThrowBadValue(label.string() + ": object", std::to_string(object),
                  "a label the image holds");
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
