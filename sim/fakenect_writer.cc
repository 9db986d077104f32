#include "sim/fakenect_writer.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>
#include <set>
#include <string>
#include <tuple>

#include "core/atomic_file.h"
#include "core/error.h"

namespace mmh::sim {
namespace {

namespace fs = std::filesystem;

constexpr size_t kPixels = static_cast<size_t>(kFakenectWidth) * kFakenectHeight;
// Size of freenect_raw_tilt_state on x86-64 (3 x int16, int8, 1 padding byte, int32 enum).
constexpr size_t kTiltStateBytes = 12;

// Record time as record.c prints it ("%f": 6 decimals).
std::string FormatTime(double time_s) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%f", time_s);
  return buffer;
}

void WriteBinary(const fs::path& path, const std::string& header, const void* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    ThrowBadValue(path.string(), "an unwritable path (" + std::string(std::strerror(errno)) + ")",
                  "a writable file in the dump folder");
  }
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) ThrowBadValue(path.string(), "a failed write", "enough space to write the dump");
}

void PutLittleEndian(std::string* bytes, uint32_t value, int count) {
  for (int i = 0; i < count; ++i) bytes->push_back(static_cast<char>((value >> (8 * i)) & 0xff));
}

}  // namespace

uint32_t KinectTimestampFromSeconds(double time_s) {
  const double ticks = std::round(time_s * kKinectTimestampClockHz);
  // Modulo 2^32 in floating point, so that the conversion is defined for any time (the counter
  // wraps after 71.6 s).
  const double wrapped = ticks - 4294967296.0 * std::floor(ticks / 4294967296.0);
  return static_cast<uint32_t>(wrapped);
}

struct FakenectWriter::Shared {
  std::mutex mutex;
  std::set<std::string> times;  // formatted record times taken
  // (time, INDEX.txt lines of the frame in playback order)
  std::vector<std::pair<double, std::vector<std::string>>> frames;
};

FakenectWriter::FakenectWriter(const fs::path& folder, const std::optional<FakenectTiltState>& tilt)
    : folder_(folder), tilt_(tilt), shared_(new Shared) {}

FakenectWriter::~FakenectWriter() = default;

void FakenectWriter::Add(double time_s, const std::vector<uint16_t>& raw_11bit,
                         const std::vector<uint8_t>& rgb) {
  const std::string where = target().string() + ", frame at " + FormatNumber(time_s) + " s";
  if (folder_.committed()) ThrowBadValue(where, "a frame after Finish()", "frames before Finish()");
  if (!std::isfinite(time_s) || time_s < 0) {
    ThrowBadValue(where, "a time of " + FormatNumber(time_s) + " s", "finite seconds >= 0");
  }
  if (raw_11bit.size() != kPixels) {
    ThrowBadValue(where + ", depth", std::to_string(raw_11bit.size()) + " pixels",
                  std::to_string(kPixels) + " = 640x480 (the only size fakenect serves)");
  }
  if (rgb.size() != 3 * kPixels) {
    ThrowBadValue(where + ", rgb", std::to_string(rgb.size()) + " bytes",
                  std::to_string(3 * kPixels) + " = 640x480x3");
  }
  for (size_t i = 0; i < kPixels; ++i) {
    if (raw_11bit[i] > kRawInvalid) {
      ThrowBadValue(where + ", depth pixel (" + std::to_string(i % kFakenectWidth) + ", " +
                        std::to_string(i / kFakenectWidth) + ")",
                    std::to_string(raw_11bit[i]), "a raw 11-bit disparity in [0, 2047]");
    }
  }
  const std::string time = FormatTime(time_s);
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    if (!shared_->times.insert(time).second) {
      ThrowBadValue(where, "the record time " + time + " of another frame",
                    "times that differ at microsecond resolution");
    }
  }
  const std::string stem = time + "-" + std::to_string(KinectTimestampFromSeconds(time_s));
  std::vector<std::string> lines = {"d-" + stem + ".pgm", "r-" + stem + ".ppm"};

  // Depth samples little-endian, as the driver's uint16 buffer lies in an x86 host's memory.
  std::string depth_bytes;
  depth_bytes.reserve(2 * kPixels);
  for (uint16_t v : raw_11bit) PutLittleEndian(&depth_bytes, v, 2);
  WriteBinary(staging() / lines[0], "P5 640 480 65535\n", depth_bytes.data(), depth_bytes.size());
  WriteBinary(staging() / lines[1], "P6 640 480 255\n", rgb.data(), rgb.size());
  if (tilt_) {
    std::string state;
    PutLittleEndian(&state, static_cast<uint16_t>(tilt_->accelerometer_x), 2);
    PutLittleEndian(&state, static_cast<uint16_t>(tilt_->accelerometer_y), 2);
    PutLittleEndian(&state, static_cast<uint16_t>(tilt_->accelerometer_z), 2);
    PutLittleEndian(&state, static_cast<uint8_t>(tilt_->tilt_angle), 1);
    state.push_back('\0');  // padding before the 4-byte enum
    PutLittleEndian(&state, static_cast<uint32_t>(tilt_->tilt_status), 4);
    lines.push_back("a-" + stem + ".dump");
    WriteBinary(staging() / lines[2], "", state.data(), kTiltStateBytes);
  }
  std::lock_guard<std::mutex> lock(shared_->mutex);
  shared_->frames.emplace_back(time_s, std::move(lines));
}

void FakenectWriter::Finish() {
  if (folder_.committed()) {
    ThrowBadValue(target().string(), "a second Finish()", "one Finish() per writer");
  }
  std::vector<std::pair<double, std::vector<std::string>>> frames;
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    frames = shared_->frames;
  }
  if (frames.empty()) ThrowBadValue(target().string(), "no frames", "at least one added frame");
  std::sort(frames.begin(), frames.end());
  // No blank line anywhere: fakenect stops at the first one.
  WriteFileAtomically(staging() / "INDEX.txt", [&](std::ostream& out) {
    for (const auto& [time, lines] : frames) {
      for (const auto& line : lines) out << line << '\n';
    }
  });
  const nlohmann::json marker = {
      {"writer", kMmhWriterName},
      {"format", "fakenect"},
      {"frames", frames.size()},
      {"width", kFakenectWidth},
      {"height", kFakenectHeight},
      {"depth", "11-bit raw disparity, uint16 little-endian, 2047 = no reading"},
      {"timestamp_clock_hz", kKinectTimestampClockHz},
      {"first_time_s", frames.front().first},
      {"last_time_s", frames.back().first}};
  WriteFileAtomically(staging() / "fakenect.json", marker.dump(2) + "\n");
  folder_.Commit();
}

std::vector<uint16_t> RawDisparityFromDepth(const RgbdFrame& frame,
                                            const KinectCalibration& calibration) {
  const size_t pixels = static_cast<size_t>(frame.depth_intrinsics.pixel_count());
  if (frame.depth.size() != pixels) {
    ThrowBadValue("frame " + std::to_string(frame.index) + ", depth",
                  std::to_string(frame.depth.size()) + " pixels",
                  std::to_string(pixels) + " = width x height of its depth intrinsics");
  }
  std::vector<uint16_t> raw(pixels, static_cast<uint16_t>(kRawInvalid));
  for (size_t i = 0; i < pixels; ++i) {
    if (frame.depth[i] == 0) continue;
    const int value = RawFromDepth(frame.depth[i] * frame.depth_scale, calibration);
    if (value >= 0 && value < kRawInvalid) raw[i] = static_cast<uint16_t>(value);
  }
  return raw;
}

}  // namespace mmh::sim
