// Frames from a real Kinect v1 through libfreenect (Debian libfreenect-dev), or from a fakenect
// dump: the same code runs against Debian's fakenect library (LD_LIBRARY_PATH=
// /usr/lib/x86_64-linux-gnu/fakenect, FAKENECT_PATH=<dump>), which replays a recording through
// libfreenect's API. libfreenect stays inside freenect_source.cc.
//
// The device delivers 640x480 raw 11-bit disparity (FREENECT_DEPTH_11BIT, the only depth mode
// Debian's fakenect 0.5.3 serves) and 8-bit RGB video at 30 Hz on two streams; a frame is emitted
// when a new depth image and a new video image have both arrived. Depth is converted to the TUM
// unit by the Kinect's disparity law z = s f b / (raw_offset - raw) (DESIGN.md, "Kinect v1
// model"), 2047 = no reading. Timestamps are the device's 60 MHz frame counter, unwrapped (it
// wraps every 71.6 s) and counted from the first depth frame.
#pragma once

#include <memory>
#include <string>

#include "core/camera.h"
#include "track/frame_source.h"

namespace mmh::track {

struct FreenectOptions {
  // Which Kinect (libfreenect's device index).
  int device_index = 0;
  // Stop after this many frames (0: until the stream ends, e.g. the end of a fakenect dump).
  int max_frames = 0;
  // Intrinsics of the delivered images (ROS defaults for the Kinect v1: 525 / 319.5 / 239.5; with
  // depth taken as registered to colour, as the simulator's dumps are).
  PinholeIntrinsics intrinsics;
  // The disparity law: the IR camera's focal length [px], the projector baseline [m], 1/8-pixel
  // disparity steps and the raw offset (sim's KinectCalibration defaults; NYU's calibration
  // z = 351.3 / (1092.5 - raw) corresponds to s f b = 351.3).
  double ir_focal_length = 580.0;
  double baseline = 0.075;
  int subpixel_steps = 8;
  double raw_offset = 1092.5;
  // Give up when this many freenect_process_events calls in a row bring no frame (a stalled
  // device) [calls].
  int max_idle_events = 200;

  template <class V>
  void VisitFields(V& v) {
    v("device_index", device_index);
    v("max_frames", max_frames);
    v("intrinsics", intrinsics);
    v("ir_focal_length", ir_focal_length);
    v("baseline", baseline);
    v("subpixel_steps", subpixel_steps);
    v("raw_offset", raw_offset);
    v("max_idle_events", max_idle_events);
  }
  // intrinsics 640x480 (the only size libfreenect serves here), positive law constants,
  // raw_offset in (1024, 4096), counts >= 0 / >= 1.
  void Validate(const std::string& prefix) const;
};

// Depth [TUM units of `depth_scale` m, 0 = missing] of a raw 11-bit disparity: round(z /
// depth_scale) with z = s f b / (raw_offset - raw); 0 for 2047, for raw >= raw_offset and for
// depths beyond the uint16 range.
uint16_t DepthUnitsFromRaw(uint16_t raw, const FreenectOptions& options, double depth_scale);

class FreenectFrameSource : public FrameSource {
 public:
  // Opens the device and starts both streams. No device (libfreenect sees none, or the index is
  // out of range), an unsupported mode or a failed start are InputErrors saying so.
  explicit FreenectFrameSource(const FreenectOptions& options);
  ~FreenectFrameSource() override;
  FreenectFrameSource(const FreenectFrameSource&) = delete;
  FreenectFrameSource& operator=(const FreenectFrameSource&) = delete;

  // The next frame; false when the stream ends (fakenect's end of dump, max_frames reached).
  // A device that stops delivering for max_idle_events calls is an InputError.
  bool Next(RgbdFrame* frame) override;
  std::string Describe() const override;
  int size() const override { return options_.max_frames > 0 ? options_.max_frames : -1; }

 private:
  struct Impl;
  FreenectOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mmh::track
