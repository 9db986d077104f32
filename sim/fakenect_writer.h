// Writes libfreenect "fakenect" dumps, so that unchanged libfreenect capture code can run on
// simulated frames by loading fakenect's libfreenect.so instead of the real one (Debian:
// /usr/lib/x86_64-linux-gnu/fakenect/libfreenect.so, with FAKENECT_PATH=<dump folder>).
//
// The format, as read from the sources (OpenKinect/libfreenect fakenect/fakenect.c, record.c and
// platform.h at upstream master; Debian's README.fakenect; and the disassembly of Debian 12's
// fakenect build, libfreenect 1:0.5.3-3, whose behaviour differs from master where noted):
//
// - The folder holds INDEX.txt: one file name per line (relative to the folder), '\n'-terminated,
//   in playback order. fakenect reads one line per freenect_process_events() call; an empty line
//   or the end of the file ends playback (0.5.3 returns -1 and prints "No more lines"; master
//   starts over unless FAKENECT_LOOP=0). A listed file that cannot be opened makes fakenect
//   exit(1), so every listed file must exist.
// - A file name is parsed with sscanf("%c-%lf-%u-%*s"): type, record time, device timestamp.
//   record.c writes "<type>-<time %f>-<timestamp %u>.<ext>": 'd' depth (.pgm), 'r' video (.ppm),
//   'a' accelerometer (.dump). The time is the host's wall clock in seconds when the frame was
//   recorded; the timestamp is the Kinect's 32-bit frame counter of a 60 MHz clock (libfreenect
//   issues #681 and #465), which wraps after 71.6 s.
// - Depth: "P5 640 480 65535\n" then 640x480 uint16 samples in host byte order (little-endian on
//   x86, against the PGM convention), the 11-bit raw disparity as the driver delivers it, 2047 =
//   no reading. fakenect ignores the header: it skips to the first '\n' and copies mode.bytes =
//   614400 bytes, so the file must hold exactly that much after the header. The NYU Depth V2 raw
//   dumps are files of this kind (core/image_io.h ReadNyuRawDisparity reads both).
// - Video: "P6 640 480 255\n" then 640x480x3 bytes RGB; 921600 bytes are copied the same way.
// - Accelerometer: the raw bytes of freenect_raw_tilt_state (12 bytes on x86-64: int16
//   accelerometer_x, _y, _z in counts, FREENECT_COUNTS_PER_G = 819 per g; int8 tilt_angle in half
//   degrees; one padding byte; int32 tilt_status, 0 = stopped). A file of another size is ignored
//   with a warning; before the first 'a' line the state is all zeros.
// - Modes: only FREENECT_RESOLUTION_MEDIUM (640x480) exists (others hit an assert). Debian's
//   0.5.3 serves FREENECT_DEPTH_11BIT and FREENECT_VIDEO_RGB only, set_*_mode accepts anything
//   and keeps serving those; master adds DEPTH_MM and DEPTH_REGISTERED (needing a device.json of
//   registration parameters) and VIDEO_YUV_RAW (converted from the RGB dump). 10-bit packed and
//   IR modes are never served.
// - Callbacks get the fake device, a buffer and the timestamp from the file name: the buffer set
//   with freenect_set_{depth,video}_buffer (copied into), else (0.5.3) a pointer into fakenect's
//   copy of the file, valid only during the callback.
// - Pacing: before handling a line, fakenect sleeps (time - previous time) minus the wall time
//   spent since the previous line, so playback keeps the recorded rhythm; a previous time of 0 is
//   taken as "none" (no sleep), so a dump starting at time 0 plays its first interval unpaced.
//   Lines of equal time (a depth and a video frame of one instant) follow without sleeping.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "core/rgbd_folder.h"
#include "core/rgbd_frame.h"
#include "sim/kinect_model.h"

namespace mmh::sim {

// The only frame size fakenect serves [px].
inline constexpr int kFakenectWidth = 640;
inline constexpr int kFakenectHeight = 480;
// Kinect v1 frame timestamps count a 60 MHz clock in 32 bits [Hz].
inline constexpr double kKinectTimestampClockHz = 60e6;

// The device timestamp of a frame at `time_s` seconds: round(time_s * 60 MHz) modulo 2^32.
uint32_t KinectTimestampFromSeconds(double time_s);

// freenect_raw_tilt_state as fakenect plays it back (see the format notes above).
struct FakenectTiltState {
  int16_t accelerometer_x = 0;  // [counts], 819 per g
  int16_t accelerometer_y = 0;
  int16_t accelerometer_z = 0;
  int8_t tilt_angle = 0;    // [half degrees]: freenect_get_tilt_degs returns tilt_angle / 2
  int32_t tilt_status = 0;  // freenect_tilt_status_code: 0 stopped, 1 limit, 4 moving
};

// Writes a dump through a StagedFolder (core/rgbd_folder.h): Finish() moves it into place with
// INDEX.txt and a fakenect.json marker ("writer": "mmh"); a writer destroyed without Finish()
// leaves nothing; an existing target is replaced only when empty or written by mmh.
// Add() may be called from several threads; INDEX.txt is sorted by time in Finish().
class FakenectWriter {
 public:
  // With `tilt`, every frame is followed by an accelerometer dump of that state (as record.c
  // writes after every event), so freenect_get_tilt_state() reports it.
  explicit FakenectWriter(const std::filesystem::path& folder,
                          const std::optional<FakenectTiltState>& tilt = std::nullopt);
  ~FakenectWriter();
  FakenectWriter(const FakenectWriter&) = delete;
  FakenectWriter& operator=(const FakenectWriter&) = delete;

  // One depth and one video frame recorded at `time_s` seconds (finite, >= 0, distinct from every
  // other frame's at microsecond resolution). raw_11bit: 640x480 row-major, values in [0, 2047],
  // 2047 = no reading; rgb: 640x480x3 bytes R, G, B. InputError naming the frame otherwise.
  void Add(double time_s, const std::vector<uint16_t>& raw_11bit, const std::vector<uint8_t>& rgb);

  // Writes INDEX.txt (depth, video, accelerometer lines per frame, frames by time) and the marker,
  // then moves the dump into place. At least one frame must have been added.
  void Finish();

  const std::filesystem::path& target() const { return folder_.target(); }
  const std::filesystem::path& staging() const { return folder_.staging(); }

 private:
  struct Shared;  // the frame list and its mutex

  StagedFolder folder_;
  std::optional<FakenectTiltState> tilt_;
  std::unique_ptr<Shared> shared_;
};

// The raw 11-bit disparity a Kinect v1 would report for a depth frame: raw = RawFromDepth(z)
// (sim/kinect_model.h) per pixel, 2047 where the depth is missing or the raw value falls outside
// [0, 2046]. Lattice depths stored in TUM units (0.2 mm, finer than the lattice step of >= 0.7 mm
// at 0.5 m) map back to their exact raw values. The result has the frame's size; note that a real
// Kinect reports raw disparity in the unregistered IR camera, this is the same image re-encoded.
std::vector<uint16_t> RawDisparityFromDepth(const RgbdFrame& frame,
                                            const KinectCalibration& calibration);

}  // namespace mmh::sim
