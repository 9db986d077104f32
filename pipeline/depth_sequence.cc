#include "pipeline/depth_sequence.h"

#include <string>

#include "core/error.h"
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

}  // namespace mmh::pipeline
