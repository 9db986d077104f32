// A reader of MATLAB level-5 MAT-files (the format of YCB-Video's per-frame `-meta.mat`): the
// numeric arrays of a file, compressed (miCOMPRESSED, zlib) or not, converted to double. Cell,
// struct, sparse, char and complex arrays are skipped (their names are listed, so a missing field
// can be told from an unsupported one). Format: MathWorks, "MAT-File Format", R2023a, ch. 1.
//
// The plain-text export of such a file (YCB-Video's `-meta.txt`, see ReadMatText) is read into
// the same structure.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace mmh::track {

// A numeric array: its dimensions and its values in MATLAB's column-major order.
struct MatArray {
  std::vector<int64_t> dims;
  std::vector<double> values;

  int64_t size() const { return static_cast<int64_t>(values.size()); }
  // Element (i, j, k) of a 3-D array (k = 0 for a matrix), column-major.
  double at(int64_t i, int64_t j, int64_t k = 0) const {
    return values[static_cast<size_t>(i + dims[0] * (j + (dims.size() > 1 ? dims[1] : 1) * k))];
  }
};

struct MatFile {
  std::map<std::string, MatArray> arrays;
  // Names of the variables that are not numeric (cell, struct, char, sparse, complex).
  std::vector<std::string> skipped;

  // The array `name` with `expected_dims` (-1: any extent); InputError naming `file`, the
  // variable, its dimensions and what was expected otherwise (or when it is missing).
  const MatArray& Get(const std::string& name, const std::vector<int64_t>& expected_dims,
                      const std::filesystem::path& file) const;
};

// Reads a level-5 MAT-file. A file that is not one (header, version, byte order), truncated or
// corrupt (a tag running past its end, a zlib stream that does not inflate, values that do not
// fill the dimensions) is an InputError naming the file and the byte offset.
MatFile ReadMatFile(const std::filesystem::path& path);

// Reads the plain-text export of a MAT-file: per variable a line `name: d1 d2 [d3]` followed by
// the values in column-major order, whitespace separated, on any number of lines; `#` starts a
// comment. Errors name the file and the line.
MatFile ReadMatText(const std::filesystem::path& path);

}  // namespace mmh::track
