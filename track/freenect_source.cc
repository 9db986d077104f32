#include "track/freenect_source.h"

#include <libfreenect.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/error.h"

namespace mmh::track {
namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr uint16_t kNoReading = 2047;

}  // namespace

void FreenectOptions::Validate(const std::string& prefix) const {
  if (device_index < 0) {
    ThrowBadValue(prefix + ".device_index", std::to_string(device_index), "an index >= 0");
  }
  if (max_frames < 0) {
    ThrowBadValue(prefix + ".max_frames", std::to_string(max_frames), ">= 0 (0: all)");
  }
  intrinsics.Validate(prefix + ".intrinsics");
  if (intrinsics.width != kWidth || intrinsics.height != kHeight) {
    ThrowBadValue(prefix + ".intrinsics",
                  std::to_string(intrinsics.width) + "x" + std::to_string(intrinsics.height),
                  "640x480, the only resolution libfreenect serves for depth and RGB together");
  }
  RequirePositive(ir_focal_length, prefix + ".ir_focal_length", "px");
  RequirePositive(baseline, prefix + ".baseline", "m");
  if (subpixel_steps < 1 || subpixel_steps > 64) {
    ThrowBadValue(prefix + ".subpixel_steps", std::to_string(subpixel_steps),
                  "an integer in [1, 64]");
  }
  RequireFinite(raw_offset, prefix + ".raw_offset");
  if (!(raw_offset > 1024 && raw_offset < 4096)) {
    ThrowBadValue(prefix + ".raw_offset", FormatNumber(raw_offset), "a value in (1024, 4096)");
  }
  if (max_idle_events < 1) {
    ThrowBadValue(prefix + ".max_idle_events", std::to_string(max_idle_events), ">= 1");
  }
}

uint16_t DepthUnitsFromRaw(uint16_t raw, const FreenectOptions& options, double depth_scale) {
  if (raw >= kNoReading || raw >= options.raw_offset) return 0;
  const double lattice_constant =
      options.subpixel_steps * options.ir_focal_length * options.baseline;
  const double z = lattice_constant / (options.raw_offset - raw);
  const double units = std::round(z / depth_scale);
  if (!(units >= 1 && units <= std::numeric_limits<uint16_t>::max())) return 0;
  return static_cast<uint16_t>(units);
}

struct FreenectFrameSource::Impl {
  freenect_context* context = nullptr;
  freenect_device* device = nullptr;
  std::vector<uint16_t> raw_depth;
  std::vector<uint8_t> rgb;
  bool new_depth = false;
  bool new_video = false;
  uint32_t depth_timestamp = 0;
  // Unwrapping of the 32-bit 60 MHz counter.
  bool have_first = false;
  uint32_t last_timestamp = 0;
  uint64_t unwrapped = 0;
  int emitted = 0;
  bool ended = false;

  static void OnDepth(freenect_device* device, void* data, uint32_t timestamp) {
    auto* self = static_cast<Impl*>(freenect_get_user(device));
    const auto* samples = static_cast<const uint16_t*>(data);
    self->raw_depth.assign(samples, samples + kWidth * kHeight);
    self->depth_timestamp = timestamp;
    self->new_depth = true;
  }
  static void OnVideo(freenect_device* device, void* data, uint32_t) {
    auto* self = static_cast<Impl*>(freenect_get_user(device));
    const auto* bytes = static_cast<const uint8_t*>(data);
    self->rgb.assign(bytes, bytes + 3 * kWidth * kHeight);
    self->new_video = true;
  }

  ~Impl() {
    if (device) {
      freenect_stop_depth(device);
      freenect_stop_video(device);
      freenect_close_device(device);
    }
    if (context) freenect_shutdown(context);
  }
};

FreenectFrameSource::FreenectFrameSource(const FreenectOptions& options)
    : options_(options), impl_(std::make_unique<Impl>()) {
  options_.Validate("freenect");
  if (freenect_init(&impl_->context, nullptr) < 0) {
    impl_->context = nullptr;
    throw InputError("freenect: libfreenect could not be initialised (no USB access?)");
  }
  freenect_set_log_level(impl_->context, FREENECT_LOG_ERROR);
  freenect_select_subdevices(impl_->context, FREENECT_DEVICE_CAMERA);
  const int devices = freenect_num_devices(impl_->context);
  if (devices <= options_.device_index) {
    ThrowBadValue("freenect.device_index", std::to_string(options_.device_index),
                  "the index of a connected Kinect v1, but libfreenect finds " +
                      std::to_string(std::max(devices, 0)) + " device(s)");
  }
  if (freenect_open_device(impl_->context, &impl_->device, options_.device_index) < 0) {
    impl_->device = nullptr;
    throw InputError("freenect: Kinect " + std::to_string(options_.device_index) +
                     " could not be opened (in use, or no permission for its USB device)");
  }
  freenect_set_user(impl_->device, impl_.get());
  const freenect_frame_mode depth_mode =
      freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_DEPTH_11BIT);
  const freenect_frame_mode video_mode =
      freenect_find_video_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_VIDEO_RGB);
  if (!depth_mode.is_valid || !video_mode.is_valid || depth_mode.bytes != 2 * kWidth * kHeight ||
      video_mode.bytes != 3 * kWidth * kHeight ||
      freenect_set_depth_mode(impl_->device, depth_mode) < 0 ||
      freenect_set_video_mode(impl_->device, video_mode) < 0) {
    throw InputError("freenect: the device does not offer 640x480 11-bit depth and RGB video");
  }
  freenect_set_depth_callback(impl_->device, &Impl::OnDepth);
  freenect_set_video_callback(impl_->device, &Impl::OnVideo);
  if (freenect_start_depth(impl_->device) < 0 || freenect_start_video(impl_->device) < 0) {
    throw InputError("freenect: the depth or video stream could not be started");
  }
}

FreenectFrameSource::~FreenectFrameSource() = default;

bool FreenectFrameSource::Next(RgbdFrame* frame) {
  frame_error_.clear();
  Impl& s = *impl_;
  if (s.ended || (options_.max_frames > 0 && s.emitted >= options_.max_frames)) return false;
  int idle = 0;
  while (!(s.new_depth && s.new_video)) {
    const bool had_depth = s.new_depth, had_video = s.new_video;
    if (freenect_process_events(s.context) < 0) {
      // fakenect's end of dump (a real device's failure looks the same to libfreenect's API).
      s.ended = true;
      return false;
    }
    if (s.new_depth != had_depth || s.new_video != had_video) {
      idle = 0;
    } else if (++idle >= options_.max_idle_events) {
      throw InputError("freenect: no frame after " + std::to_string(idle) +
                       " calls of freenect_process_events (device stalled or unplugged?)");
    }
  }
  s.new_depth = s.new_video = false;
  if (!s.have_first) {
    s.have_first = true;
  } else {
    s.unwrapped += static_cast<uint32_t>(s.depth_timestamp - s.last_timestamp);  // mod 2^32
  }
  s.last_timestamp = s.depth_timestamp;

  frame->index = s.emitted++;
  frame->timestamp = static_cast<double>(s.unwrapped) / 60e6;
  frame->depth_intrinsics = options_.intrinsics;
  frame->color_intrinsics = options_.intrinsics;
  frame->color_T_depth = Rigid3::Identity();
  frame->depth_scale = kTumDepthScale;
  frame->depth.resize(s.raw_depth.size());
  for (size_t i = 0; i < s.raw_depth.size(); ++i) {
    frame->depth[i] = DepthUnitsFromRaw(s.raw_depth[i], options_, frame->depth_scale);
  }
  frame->rgb = s.rgb;
  return true;
}

std::string FreenectFrameSource::Describe() const {
  return "freenect device " + std::to_string(options_.device_index);
}

}  // namespace mmh::track
