#include "core/internal/ply_mesh_reader.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <set>
#include <vector>

#include "core/error.h"
#include "core/error_text.h"
#include "core/internal/mesh_builder.h"
#include "core/text_parsing.h"

namespace mmh::internal {
namespace {

enum class Format { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

enum class Type { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

struct TypeInfo {
  const char* names[2];  // the PLY 1.0 name and the sized alias
  Type type;
  int bytes;
};

constexpr TypeInfo kTypes[] = {
    {{"char", "int8"}, Type::kInt8, 1},       {{"uchar", "uint8"}, Type::kUint8, 1},
    {{"short", "int16"}, Type::kInt16, 2},    {{"ushort", "uint16"}, Type::kUint16, 2},
    {{"int", "int32"}, Type::kInt32, 4},      {{"uint", "uint32"}, Type::kUint32, 4},
    {{"float", "float32"}, Type::kFloat32, 4}, {{"double", "float64"}, Type::kFloat64, 8},
};

int ByteSize(Type type) { return kTypes[static_cast<int>(type)].bytes; }
bool IsInteger(Type type) { return type != Type::kFloat32 && type != Type::kFloat64; }
const char* TypeName(Type type) { return kTypes[static_cast<int>(type)].names[0]; }

// The largest value of an integer type (colours are scaled by it).
double TypeMax(Type type) {
  switch (type) {
    case Type::kInt8: return 127;
    case Type::kUint8: return 255;
    case Type::kInt16: return 32767;
    case Type::kUint16: return 65535;
    case Type::kInt32: return 2147483647.0;
    case Type::kUint32: return 4294967295.0;
    default: return 1;
  }
}
double TypeMin(Type type) {
  switch (type) {
    case Type::kInt8: return -128;
    case Type::kInt16: return -32768;
    case Type::kInt32: return -2147483648.0;
    default: return 0;
  }
}

struct Property {
  std::string name;
  Type type = Type::kFloat32;  // of the items for a list
  bool is_list = false;
  Type count_type = Type::kUint8;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
  int header_line = 0;
};

struct Header {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  std::size_t body_start = 0;  // byte offset after the end_header line
  int body_line = 0;           // line number of the body's first line
};

// Reads the header: every line up to "end_header".
Header ReadHeader(std::string_view bytes, const std::string& where) {
  Header header;
  bool have_format = false;
  // Names seen (sets: a header of 10^5 properties must not take quadratic time).
  std::set<std::string> element_names;
  std::set<std::string> property_names;  // of the current element
  std::size_t pos = 0;
  for (int line_number = 1;; ++line_number) {
    const std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) {
      ThrowBadValue(where, "a PLY header without an end_header line", "a valid ply mesh");
    }
    const std::string_view line = Trim(bytes.substr(pos, end - pos));
    pos = end + 1;
    const std::string at = where + ":" + std::to_string(line_number);
    const auto fields = SplitFields(line, " \t");
    if (line_number == 1) {
      if (line != "ply") ThrowBadValue(at, Quote(line), "'ply' (the first line of a PLY file)");
      continue;
    }
    if (fields.empty()) continue;
    const std::string_view keyword = fields[0];
    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") {
      if (!have_format) ThrowBadValue(at, "end_header before a format line", "a format line");
      header.body_start = pos;
      header.body_line = line_number + 1;
      return header;
    }
    if (keyword == "format") {
      static constexpr std::pair<const char*, Format> kFormats[] = {
          {"ascii", Format::kAscii},
          {"binary_little_endian", Format::kBinaryLittleEndian},
          {"binary_big_endian", Format::kBinaryBigEndian}};
      const std::pair<const char*, Format>* found = nullptr;
      for (const auto& format : kFormats) {
        if (fields.size() == 3 && fields[1] == format.first) found = &format;
      }
      if (have_format || found == nullptr || (fields[2] != "1.0" && fields[2] != "1")) {
        ThrowBadValue(at, Quote(line),
                      have_format ? "one format line"
                                  : "'format ascii 1.0', 'format binary_little_endian 1.0' or "
                                    "'format binary_big_endian 1.0'");
      }
      header.format = found->second;
      have_format = true;
    } else if (keyword == "element") {
      std::uint64_t count = 0;
      const bool ok = fields.size() == 3 &&
                      std::from_chars(fields[2].data(), fields[2].data() + fields[2].size(), count)
                              .ptr == fields[2].data() + fields[2].size() &&
                      !fields[2].empty() && fields[2][0] != '-';
      if (!ok) ThrowBadValue(at, Quote(line), "'element NAME COUNT' with a count >= 0");
      if (!element_names.insert(std::string(fields[1])).second) {
        ThrowBadValue(at, "a second element " + Quote(fields[1]), "each element once");
      }
      header.elements.push_back({std::string(fields[1]), count, {}, line_number});
      property_names.clear();
    } else if (keyword == "property") {
      if (header.elements.empty()) {
        ThrowBadValue(at, Quote(line), "a property after its element line");
      }
      auto type_of = [&](std::string_view name) -> Type {
        for (const TypeInfo& info : kTypes) {
          if (name == info.names[0] || name == info.names[1]) return info.type;
        }
        ThrowBadValue(at, "type " + Quote(name),
                      "one of char, uchar, short, ushort, int, uint, float, double (or int8, "
                      "uint8, int16, uint16, int32, uint32, float32, float64)");
      };
      Property property;
      if (fields.size() == 5 && fields[1] == "list") {
        property.is_list = true;
        property.count_type = type_of(fields[2]);
        property.type = type_of(fields[3]);
        property.name = std::string(fields[4]);
        if (!IsInteger(property.count_type)) {
          ThrowBadValue(at, "list count type " + Quote(fields[2]), "an integer type");
        }
      } else if (fields.size() == 3 && fields[1] != "list") {
        property.type = type_of(fields[1]);
        property.name = std::string(fields[2]);
      } else {
        ThrowBadValue(at, Quote(line), "'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
      }
      if (!property_names.insert(property.name).second) {
        ThrowBadValue(at, "a second property " + Quote(property.name), "each property once");
      }
      header.elements.back().properties.push_back(property);
    } else {
      ThrowBadValue(at, Quote(line),
                    "a PLY header line (format, element, property, comment, obj_info or "
                    "end_header)");
    }
  }
}

// Values of the body, one at a time, in either encoding. Errors name the element and item and
// the ASCII line or the binary byte offset.
class BodyReader {
 public:
  BodyReader(std::string_view bytes, const Header& header, const std::string& where)
      : bytes_(bytes), format_(header.format), where_(where), pos_(header.body_start),
        line_number_(header.body_line - 1) {}

  // Starts item `index` of `element` (an ASCII line).
  void BeginItem(const Element& element, std::uint64_t index) {
    element_ = &element;
    index_ = index;
    if (format_ != Format::kAscii) return;
    tokens_.clear();
    next_token_ = 0;
    while (tokens_.empty()) {
      if (pos_ >= bytes_.size()) {
        Fail("the end of the file", "a line for each of the " + std::to_string(element.count) +
                                        " " + element.name + " items the header declares");
      }
      std::size_t end = bytes_.find('\n', pos_);
      if (end == std::string_view::npos) end = bytes_.size();
      line_ = bytes_.substr(pos_, end - pos_);
      tokens_ = SplitFields(line_, " \t\r");
      pos_ = end + 1;
      ++line_number_;
    }
  }

  // Ends the item: an ASCII line must hold nothing more.
  void EndItem() {
    if (format_ == Format::kAscii && next_token_ != tokens_.size()) {
      Fail(Quote(Trim(line_)), std::to_string(next_token_) + " values (the properties of " +
                                   element_->name + ")");
    }
  }

  // The next value, of `type`, for `property`.
  double Read(Type type, const Property& property) {
    if (format_ == Format::kAscii) return ReadAscii(type, property);
    const int size = ByteSize(type);
    if (bytes_.size() - std::min(pos_, bytes_.size()) < static_cast<std::size_t>(size)) {
      Fail("the end of the file", std::to_string(size) + " more bytes for property " +
                                      Quote(property.name));
    }
    unsigned char raw[8];
    std::memcpy(raw, bytes_.data() + pos_, size);
    pos_ += size;
    const bool file_little = format_ == Format::kBinaryLittleEndian;
    if (file_little != (std::endian::native == std::endian::little)) {
      std::reverse(raw, raw + size);
    }
    switch (type) {
      case Type::kInt8: return Decode<std::int8_t>(raw);
      case Type::kUint8: return Decode<std::uint8_t>(raw);
      case Type::kInt16: return Decode<std::int16_t>(raw);
      case Type::kUint16: return Decode<std::uint16_t>(raw);
      case Type::kInt32: return Decode<std::int32_t>(raw);
      case Type::kUint32: return Decode<std::uint32_t>(raw);
      case Type::kFloat32: return Decode<float>(raw);
      case Type::kFloat64: return Decode<double>(raw);
    }
    return 0;
  }

  // Skips `count` values of `type` (list items not used), checking that the data holds them.
  void Skip(Type type, std::uint64_t count, const Property& property) {
    if (format_ == Format::kAscii) {
      for (std::uint64_t i = 0; i < count; ++i) Read(type, property);
      return;
    }
    const std::uint64_t left = bytes_.size() - std::min(pos_, bytes_.size());
    if (count > left / ByteSize(type)) {
      Fail("the end of the file", std::to_string(count) + " values of property " +
                                      Quote(property.name));
    }
    pos_ += count * ByteSize(type);
  }

  // Bytes not read yet (binary) or an upper bound of the lines left (ASCII).
  std::uint64_t left() const { return bytes_.size() - std::min(pos_, bytes_.size()); }

  // After the last element: nothing but white space may follow.
  void ExpectEnd() const {
    for (std::size_t i = pos_; i < bytes_.size(); ++i) {
      const char c = bytes_[i];
      if (c != ' ' && c != '\t' && c != '\r' && c != '\n' && c != '\0') {
        const std::string at =
            format_ == Format::kAscii ? where_ + ":" + std::to_string(line_number_ + 1)
                                      : where_ + " (byte " + std::to_string(pos_) + ")";
        ThrowBadValue(at, std::to_string(bytes_.size() - pos_) + " bytes after the last element",
                      "the end of the file (the header's element counts)");
      }
    }
  }

  [[noreturn]] void Fail(const std::string& value, const std::string& expected) const {
    std::string at = where_;
    if (format_ == Format::kAscii) {
      at += ":" + std::to_string(line_number_);
    }
    at += ": " + element_->name + " " + std::to_string(index_);
    if (format_ != Format::kAscii) at += " (byte " + std::to_string(pos_) + ")";
    ThrowBadValue(at, value, expected);
  }

 private:
  template <typename T>
  static double Decode(const unsigned char* raw) {
    T value;
    std::memcpy(&value, raw, sizeof value);
    return static_cast<double>(value);
  }

  double ReadAscii(Type type, const Property& property) {
    if (next_token_ >= tokens_.size()) {
      Fail("a line of " + std::to_string(tokens_.size()) + " values",
           "more values: property " + Quote(property.name) + " is missing");
    }
    const std::string_view token = tokens_[next_token_++];
    double value = 0;
    if (!ParseDouble(token, &value) ||
        (IsInteger(type) &&
         (value != std::floor(value) || value < TypeMin(type) || value > TypeMax(type)))) {
      Fail(Quote(token) + " for property " + Quote(property.name),
           std::string(IsInteger(type) ? "an integer of type " : "a number of type ") +
               TypeName(type));
    }
    return value;
  }

  std::string_view bytes_;
  Format format_;
  const std::string& where_;
  std::size_t pos_;
  int line_number_;
  const Element* element_ = nullptr;
  std::uint64_t index_ = 0;
  std::string_view line_;
  std::vector<std::string_view> tokens_;
  std::size_t next_token_ = 0;
};

// Index of the scalar property named one of `names`, or kNone.
constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
std::size_t FindScalar(const Element& element, std::initializer_list<const char*> names) {
  for (std::size_t i = 0; i < element.properties.size(); ++i) {
    for (const char* name : names) {
      if (element.properties[i].name == name && !element.properties[i].is_list) return i;
    }
  }
  return kNone;
}

// Index of the face element's vertex index list, or kNone.
std::size_t FindIndexList(const Element& element) {
  for (std::size_t i = 0; i < element.properties.size(); ++i) {
    const std::string& name = element.properties[i].name;
    if ((name == "vertex_indices" || name == "vertex_index") && element.properties[i].is_list) {
      return i;
    }
  }
  return kNone;
}

// The fewest bytes (binary) or lines (ASCII) one item of `element` takes: the element's count
// must fit in the bytes left, checked before reading so that a header that claims 10^18 items
// fails at once.
std::uint64_t MinItemSize(const Element& element, Format format) {
  if (format == Format::kAscii) return 2;  // a value and a line break (the last may lack it)
  std::uint64_t size = 0;
  for (const Property& p : element.properties) size += ByteSize(p.is_list ? p.count_type : p.type);
  return size;
}

}  // namespace

TriangleMesh ReadPlyMesh(std::string_view bytes, const std::string& where) {
  const Header header = ReadHeader(bytes, where);
  const Element* vertex_element = nullptr;
  for (const Element& element : header.elements) {
    const std::string at = where + ":" + std::to_string(element.header_line);
    if (element.properties.empty() && element.count > 0) {
      ThrowBadValue(at, "element " + Quote(element.name) + " without properties",
                    "at least one property per element");
    }
    if (element.name == "vertex") {
      vertex_element = &element;
      for (const char* axis : {"x", "y", "z"}) {
        if (FindScalar(element, {axis}) == kNone) {
          ThrowBadValue(at, "a vertex element without a scalar property " + Quote(axis),
                        "scalar properties x, y and z");
        }
      }
    }
    if (element.name == "face" && FindIndexList(element) == kNone) {
      ThrowBadValue(at, "a face element without a vertex_indices list",
                    "'property list uchar int vertex_indices' (or vertex_index)");
    }
  }

  MeshBuilder builder(where);
  BodyReader body(bytes, header, where);
  std::vector<double> values;
  std::vector<std::uint32_t> corners;
  for (const Element& element : header.elements) {
    if (element.count > 0 && element.count > (body.left() + 1) / MinItemSize(element, header.format)) {
      ThrowBadValue(where + ":" + std::to_string(element.header_line),
                    "element " + Quote(element.name) + " of " + std::to_string(element.count) +
                        " items",
                    "no more items than the " + std::to_string(body.left()) +
                        " bytes after the header can hold");
    }
    const bool is_vertex = &element == vertex_element;
    const bool is_face = element.name == "face";
    std::size_t xyz[3] = {kNone, kNone, kNone};
    std::size_t rgb[3] = {kNone, kNone, kNone};
    if (is_vertex) {
      xyz[0] = FindScalar(element, {"x"});
      xyz[1] = FindScalar(element, {"y"});
      xyz[2] = FindScalar(element, {"z"});
      rgb[0] = FindScalar(element, {"red", "r", "diffuse_red"});
      rgb[1] = FindScalar(element, {"green", "g", "diffuse_green"});
      rgb[2] = FindScalar(element, {"blue", "b", "diffuse_blue"});
    }
    const std::size_t indices = is_face ? FindIndexList(element) : kNone;
    const bool colored = rgb[0] != kNone && rgb[1] != kNone && rgb[2] != kNone;
    values.resize(element.properties.size());
    for (std::uint64_t item = 0; item < element.count; ++item) {
      body.BeginItem(element, item);
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const Property& property = element.properties[p];
        if (!property.is_list) {
          values[p] = body.Read(property.type, property);
          continue;
        }
        const double count = body.Read(property.count_type, property);
        if (count < 0) {
          body.Fail("a list of " + FormatNumber(count) + " items in property " +
                        Quote(property.name),
                    "a count >= 0");
        }
        if (p != indices) {
          body.Skip(property.type, static_cast<std::uint64_t>(count), property);
          continue;
        }
        if (!IsInteger(property.type)) {
          body.Fail("vertex indices of type " + std::string(TypeName(property.type)),
                    "an integer type");
        }
        corners.clear();
        for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(count); ++k) {
          const double index = body.Read(property.type, property);
          if (index < 0 || index >= static_cast<double>(builder.vertex_count())) {
            body.Fail("vertex index " + FormatNumber(index),
                      builder.vertex_count() == 0
                          ? "vertices (the vertex element must come before the faces)"
                          : "an index from 0 to " + std::to_string(builder.vertex_count() - 1));
          }
          corners.push_back(static_cast<std::uint32_t>(index));
        }
        builder.AddPolygon(corners, kDefaultMeshColor);
      }
      body.EndItem();
      if (!is_vertex) continue;
      if (colored) {
        std::array<double, 3> color;
        for (int c = 0; c < 3; ++c) {
          color[c] = values[rgb[c]] / TypeMax(element.properties[rgb[c]].type);
        }
        builder.AddVertex(values[xyz[0]], values[xyz[1]], values[xyz[2]], color);
      } else {
        builder.AddVertex(values[xyz[0]], values[xyz[1]], values[xyz[2]]);
      }
    }
  }
  body.ExpectEnd();
  return builder.Build();
}

}  // namespace mmh::internal
