#include "track/mat_file.h"

#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace mmh::track {
namespace {

// Most elements one array may have: a level-5 element's size is a uint32 (bytes), so a binary
// file cannot hold more; the text export is held to the same.
constexpr int64_t kMaxMatElements = int64_t{1} << 32;

// Data types of the tags (MAT-File Format, table 1-1) and array classes (table 1-3).
enum MatType : uint32_t {
  kMiInt8 = 1,
  kMiUint8 = 2,
  kMiInt16 = 3,
  kMiUint16 = 4,
  kMiInt32 = 5,
  kMiUint32 = 6,
  kMiSingle = 7,
  kMiDouble = 9,
  kMiInt64 = 12,
  kMiUint64 = 13,
  kMiMatrix = 14,
  kMiCompressed = 15,
};
constexpr uint32_t kComplexFlag = 0x0800;
constexpr int kMxFirstNumericClass = 6;  // mxDOUBLE_CLASS; up to mxUINT64_CLASS = 15
constexpr int kMxLastNumericClass = 15;
constexpr size_t kHeaderBytes = 128;

struct Element {
  uint32_t type = 0;
  const uint8_t* data = nullptr;
  size_t bytes = 0;
};

// Reads the data elements of [begin, end) one at a time.
class ElementReader {
 public:
  ElementReader(const uint8_t* begin, const uint8_t* end, const std::string& where, size_t base)
      : begin_(begin), pos_(begin), end_(end), where_(where), base_(base) {}
  bool done() const { return pos_ >= end_; }

  Element Next() {
    if (end_ - pos_ < 8) Fail("a truncated tag");
    uint32_t word0, word1;
    std::memcpy(&word0, pos_, 4);
    std::memcpy(&word1, pos_ + 4, 4);
    Element e;
    if (word0 >> 16) {  // small data element: bytes and type in the first word, data in 4 bytes
      e.type = word0 & 0xffff;
      e.bytes = word0 >> 16;
      if (e.bytes > 4) Fail("a small element of " + std::to_string(e.bytes) + " bytes");
      e.data = pos_ + 4;
      pos_ += 8;
      return e;
    }
    e.type = word0;
    e.bytes = word1;
    e.data = pos_ + 8;
    if (static_cast<size_t>(end_ - e.data) < e.bytes) {
      Fail("an element of " + std::to_string(e.bytes) + " bytes past the end");
    }
    // Compressed elements are not padded; all others to 8 bytes.
    const size_t padded = e.type == kMiCompressed ? e.bytes : (e.bytes + 7) / 8 * 8;
    pos_ = e.data + std::min(padded, static_cast<size_t>(end_ - e.data));
    return e;
  }

  [[noreturn]] void Fail(const std::string& what) const {
    throw InputError(where_ + ": not a valid MAT-file: " + what + " at byte " +
                     std::to_string(base_ + (pos_ - begin_)));
  }

 private:
  const uint8_t* begin_;
  const uint8_t* pos_;
  const uint8_t* end_;
  std::string where_;
  size_t base_;
};

size_t TypeSize(uint32_t type) {
  switch (type) {
    case kMiInt8:
    case kMiUint8:
      return 1;
    case kMiInt16:
    case kMiUint16:
      return 2;
    case kMiInt32:
    case kMiUint32:
    case kMiSingle:
      return 4;
    case kMiDouble:
    case kMiInt64:
    case kMiUint64:
      return 8;
    default:
      return 0;
  }
}

template <class T>
double Load(const uint8_t* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return static_cast<double>(value);
}

double LoadValue(uint32_t type, const uint8_t* p) {
  switch (type) {
    case kMiInt8:
      return Load<int8_t>(p);
    case kMiUint8:
      return Load<uint8_t>(p);
    case kMiInt16:
      return Load<int16_t>(p);
    case kMiUint16:
      return Load<uint16_t>(p);
    case kMiInt32:
      return Load<int32_t>(p);
    case kMiUint32:
      return Load<uint32_t>(p);
    case kMiSingle:
      return Load<float>(p);
    case kMiDouble:
      return Load<double>(p);
    case kMiInt64:
      return Load<int64_t>(p);
    default:
      return Load<uint64_t>(p);
  }
}

// Parses one miMATRIX element's contents into `file`.
void ParseMatrix(const Element& matrix, const std::string& where, size_t base, MatFile* file) {
  ElementReader r(matrix.data, matrix.data + matrix.bytes, where, base);
  const Element flags = r.Next();
  if (flags.type != kMiUint32 || flags.bytes < 8) r.Fail("array flags that are not 2 uint32");
  uint32_t flag_word;
  std::memcpy(&flag_word, flags.data, 4);
  const int array_class = static_cast<int>(flag_word & 0xff);
  const Element dims_element = r.Next();
  if (dims_element.type != kMiInt32 || dims_element.bytes % 4 != 0 || dims_element.bytes < 8) {
    r.Fail("dimensions that are not int32");
  }
  MatArray array;
  int64_t count = 1;
  for (size_t i = 0; i < dims_element.bytes / 4; ++i) {
    int32_t d;
    std::memcpy(&d, dims_element.data + 4 * i, 4);
    if (d < 0) r.Fail("a negative dimension");
    array.dims.push_back(d);
    // An element's size is a uint32, so more elements than kMaxMatElements cannot be stored; the
    // check also keeps the product from overflowing (found by fuzz/mat_fuzzer.cc).
    if (d != 0 && count > kMaxMatElements / d) r.Fail("dimensions of more than 2^32 elements");
    count *= d;
  }
  const Element name_element = r.Next();
  if (name_element.type != kMiInt8) r.Fail("an array name that is not int8");
  const std::string name(reinterpret_cast<const char*>(name_element.data), name_element.bytes);
  if (array_class < kMxFirstNumericClass || array_class > kMxLastNumericClass ||
      (flag_word & kComplexFlag)) {
    file->skipped.push_back(name);
    return;
  }
  const Element real = r.Next();
  const size_t type_size = TypeSize(real.type);
  if (type_size == 0) r.Fail("variable '" + name + "' of type " + std::to_string(real.type));
  if (real.bytes != static_cast<size_t>(count) * type_size) {
    r.Fail("variable '" + name + "' with " + std::to_string(real.bytes / type_size) +
           " values for " + std::to_string(count) + " elements");
  }
  array.values.resize(static_cast<size_t>(count));
  for (int64_t i = 0; i < count; ++i) array.values[i] = LoadValue(real.type, real.data + i * type_size);
  file->arrays[name] = std::move(array);
}

std::vector<uint8_t> Inflate(const Element& e, const ElementReader& r) {
  std::vector<uint8_t> out(std::max<size_t>(1024, e.bytes * 4));
  z_stream z{};
  if (inflateInit(&z) != Z_OK) r.Fail("zlib initialisation failure");
  z.next_in = const_cast<Bytef*>(e.data);
  z.avail_in = static_cast<uInt>(e.bytes);
  int status = Z_OK;
  while (status != Z_STREAM_END) {
    if (z.total_out == out.size()) out.resize(out.size() * 2);
    z.next_out = out.data() + z.total_out;
    z.avail_out = static_cast<uInt>(out.size() - z.total_out);
    status = inflate(&z, Z_NO_FLUSH);
    if (status != Z_OK && status != Z_STREAM_END) {
      inflateEnd(&z);
      r.Fail("a compressed element that does not inflate (zlib " + std::to_string(status) + ")");
    }
    if (status == Z_OK && z.avail_in == 0 && z.avail_out > 0) {
      inflateEnd(&z);
      r.Fail("a truncated compressed element");
    }
  }
  out.resize(z.total_out);
  inflateEnd(&z);
  return out;
}

std::string Dims(const std::vector<int64_t>& dims) {
  std::string s;
  for (size_t i = 0; i < dims.size(); ++i) {
    s += (i ? "x" : "") + (dims[i] < 0 ? std::string("any") : std::to_string(dims[i]));
  }
  return s;
}

}  // namespace

const MatArray& MatFile::Get(const std::string& name, const std::vector<int64_t>& expected_dims,
                             const std::filesystem::path& file) const {
  const auto it = arrays.find(name);
  if (it == arrays.end()) {
    const bool other = std::find(skipped.begin(), skipped.end(), name) != skipped.end();
    throw InputError(file.string() + ": variable '" + name + "' " +
                     (other ? "is not a real numeric array" : "is missing") +
                     ", expected a " + Dims(expected_dims) + " numeric array");
  }
  const MatArray& a = it->second;
  // MATLAB stores at least two dimensions; trailing singleton dimensions may be dropped (a 3x4x1
  // array is stored as 3x4).
  bool ok = true;
  for (size_t i = 0; i < std::max(a.dims.size(), expected_dims.size()); ++i) {
    const int64_t have = i < a.dims.size() ? a.dims[i] : 1;
    const int64_t want = i < expected_dims.size() ? expected_dims[i] : 1;
    if (want >= 0 && have != want) ok = false;
  }
  if (!ok) {
    ThrowBadValue(file.string() + ": variable '" + name + "'", Dims(a.dims),
                  "dimensions " + Dims(expected_dims));
  }
  return a;
}

MatFile ReadMatFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open the MAT-file");
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
  const std::string where = path.string();
  if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), "MATLAB 5.0 MAT-file", 19) != 0) {
    throw InputError(where + ": not a level-5 MAT-file (its header does not start with "
                             "'MATLAB 5.0 MAT-file'; a v4 or v7.3/HDF5 file is not supported)");
  }
  if (bytes[126] != 'I' || bytes[127] != 'M') {
    throw InputError(where + ": a big-endian MAT-file (endian indicator 'MI'), expected 'IM'");
  }
  MatFile file;
  ElementReader r(bytes.data() + kHeaderBytes, bytes.data() + bytes.size(), where, kHeaderBytes);
  while (!r.done()) {
    const Element e = r.Next();
    const size_t offset = e.data - bytes.data();
    if (e.type == kMiCompressed) {
      const std::vector<uint8_t> inner = Inflate(e, r);
      ElementReader ir(inner.data(), inner.data() + inner.size(), where + " (compressed element)",
                       0);
      while (!ir.done()) {
        const Element m = ir.Next();
        if (m.type == kMiMatrix) ParseMatrix(m, where + " (compressed element)", 0, &file);
      }
    } else if (e.type == kMiMatrix) {
      ParseMatrix(e, where, offset, &file);
    }
  }
  return file;
}

MatFile ReadMatText(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open the MAT text export");
  MatFile file;
  std::string line;
  int line_number = 0;
  MatArray* current = nullptr;
  std::string current_name;
  size_t expected = 0;
  int header_line = 0;
  auto finish = [&] {
    if (current && current->values.size() != expected) {
      throw InputError(path.string() + ":" + std::to_string(header_line) + ": variable '" +
                       current_name + "' has " + std::to_string(current->values.size()) +
                       " values, expected " + std::to_string(expected) + " (its dimensions)");
    }
  };
  while (std::getline(in, line)) {
    ++line_number;
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    const size_t colon = line.find(':');
    std::istringstream tokens(colon == std::string::npos ? line : line.substr(colon + 1));
    if (colon != std::string::npos) {
      finish();
      current_name = line.substr(0, colon);
      current_name.erase(0, current_name.find_first_not_of(" \t"));
      current_name.erase(current_name.find_last_not_of(" \t") + 1);
      MatArray array;
      std::string token;
      while (tokens >> token) {
        char* end = nullptr;
        const long long d = std::strtoll(token.c_str(), &end, 10);
        if (*end != '\0' || d < 0) {
          ThrowBadValue(path.string() + ":" + std::to_string(line_number) + ": dimensions of '" +
                            current_name + "'",
                        "'" + token + "'", "non-negative integers");
        }
        array.dims.push_back(d);
      }
      if (array.dims.empty()) {
        throw InputError(path.string() + ":" + std::to_string(line_number) + ": variable '" +
                         current_name + "' without dimensions (expected 'name: d1 d2 ...')");
      }
      expected = 1;
      for (int64_t d : array.dims) {
        if (d != 0 && static_cast<int64_t>(expected) > kMaxMatElements / d) {
          ThrowBadValue(path.string() + ":" + std::to_string(line_number) + ": dimensions of '" +
                            current_name + "'",
                        line.substr(colon + 1), "at most 2^32 elements");
        }
        expected *= static_cast<size_t>(d);
      }
      file.arrays[current_name] = std::move(array);
      current = &file.arrays[current_name];
      header_line = line_number;
      continue;
    }
    std::string token;
    while (tokens >> token) {
      if (!current) {
        throw InputError(path.string() + ":" + std::to_string(line_number) +
                         ": a value before the first 'name: dims' line");
      }
      char* end = nullptr;
      const double value = std::strtod(token.c_str(), &end);
      if (*end != '\0') {
        ThrowBadValue(path.string() + ":" + std::to_string(line_number) + ": value of '" +
                          current_name + "'",
                      "'" + token + "'", "a number");
      }
      current->values.push_back(value);
    }
  }
  finish();
  return file;
}

}  // namespace mmh::track
