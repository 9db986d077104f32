// TUM trajectory files, as evo and the TUM RGB-D tools read them:
//   timestamp tx ty tz qx qy qz qw
// one pose per line, separated by spaces or tabs, '#' starts a comment line, seconds and metres,
// quaternion with w last.
#pragma once

#include <filesystem>

#include "core/trajectory.h"

namespace mmh {

// Reads and validates a TUM file. Quaternions are normalised when their norm is within 1 ± 0.01
// but not within 1e-12 of 1 (so that a file read and written again is unchanged)
// (files written with few digits); a zero or far-from-unit quaternion, a non-finite value, a line
// with the wrong number of fields, timestamps that do not increase and an empty file are
// InputErrors naming the file, the line, the value and what was expected.
Trajectory ReadTum(const std::filesystem::path& path);

// Writes atomically, every number in its shortest exact (round-trip) form, so that the same
// trajectory always gives the same bytes. An empty trajectory is an InputError. `comment` lines are
// written after '# '.
void WriteTum(const std::filesystem::path& path, const Trajectory& trajectory,
              const std::string& comment = "");

}  // namespace mmh
