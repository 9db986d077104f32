#include "track/frame_source.h"

#include <utility>

#include "core/error.h"

namespace mmh::track {

CallbackFrameSource::CallbackFrameSource(Producer produce, std::string description, int frames)
    : produce_(std::move(produce)), description_(std::move(description)), frames_(frames) {}

bool CallbackFrameSource::Next(RgbdFrame* frame) {
  frame_error_.clear();
  if (frames_ >= 0 && next_ >= frames_) return false;
  if (!produce_(next_, frame)) return false;
  ++next_;
  return true;
}

FolderFrameSource::FolderFrameSource(const std::filesystem::path& folder,
                                     const std::optional<PinholeIntrinsics>& intrinsics)
    : reader_(folder, intrinsics) {}

bool FolderFrameSource::Next(RgbdFrame* frame) {
  frame_error_.clear();
  if (next_ >= reader_.size()) return false;
  const int i = next_++;
  try {
    *frame = reader_.Read(i);
  } catch (const InputError& e) {
    // One unreadable image loses its frame, not the take (see FrameSource::Next).
    *frame = RgbdFrame();
    frame->index = i;
    frame->timestamp = reader_.depth_timestamp(i);
    frame->depth_intrinsics = reader_.camera().depth_intrinsics;
    frame->color_intrinsics = reader_.camera().color_intrinsics;
    frame->depth_scale = reader_.camera().depth_scale;
    frame_error_ = e.what();
  }
  return true;
}

std::string FolderFrameSource::Describe() const { return "folder " + reader_.folder().string(); }

}  // namespace mmh::track
