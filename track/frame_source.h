// Where the tracker's frames come from: the simulator's in-memory stream, a recorded TUM RGB-D
// folder (ours or a public sequence) or a real Kinect v1 (track/freenect_source.h). The tracker
// sees only RgbdFrames, so it runs unchanged on all of them.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "core/camera.h"
#include "core/rgbd_folder.h"
#include "core/rgbd_frame.h"

namespace mmh::track {

// A stream of frames, pulled one at a time.
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // Fills `frame` with the next frame and returns true, or returns false at the end of the stream.
  // A frame that exists but cannot be read (a truncated or corrupt image) is returned with its
  // index and timestamp, empty depth and colour, and the reason in frame_error(): the tracker
  // reports it as lost and goes on, so that one bad file loses one frame, not the take.
  virtual bool Next(RgbdFrame* frame) = 0;

  // Why the last frame returned by Next() is empty ("" when it is not).
  const std::string& frame_error() const { return frame_error_; }

  // For messages and run.json: "folder DIR", "freenect device 0", ...
  virtual std::string Describe() const = 0;

  // Number of frames when known in advance, else -1.
  virtual int size() const { return -1; }

  // The setup-time calibration files that come with the stream (scene.json of a recorded folder),
  // or empty.
  virtual std::filesystem::path folder() const { return {}; }

 protected:
  std::string frame_error_;
};

// Frames made in memory by a function, e.g. the simulator's KinectSensor::Render: produce(i, frame)
// fills frame i and returns true, or returns false when the stream ends.
class CallbackFrameSource : public FrameSource {
 public:
  using Producer = std::function<bool(int index, RgbdFrame* frame)>;
  CallbackFrameSource(Producer produce, std::string description, int frames = -1);
  bool Next(RgbdFrame* frame) override;
  std::string Describe() const override { return description_; }
  int size() const override { return frames_; }

 private:
  Producer produce_;
  std::string description_;
  int frames_;
  int next_ = 0;
};

// A TUM RGB-D folder (core/rgbd_folder.h): ours (camera.json) or a public sequence (intrinsics
// from `intrinsics` or from 'freiburg1/2/3' in the folder name). Opening checks the lists and the
// camera (InputError naming the folder); images are read per frame.
class FolderFrameSource : public FrameSource {
 public:
  explicit FolderFrameSource(const std::filesystem::path& folder,
                             const std::optional<PinholeIntrinsics>& intrinsics = std::nullopt);
  bool Next(RgbdFrame* frame) override;
  std::string Describe() const override;
  int size() const override { return reader_.size(); }
  std::filesystem::path folder() const override { return reader_.folder(); }
  const RgbdFolderReader& reader() const { return reader_; }

 private:
  RgbdFolderReader reader_;
  int next_ = 0;
};

}  // namespace mmh::track
