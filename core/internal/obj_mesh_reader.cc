#include "core/internal/obj_mesh_reader.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <system_error>
#include <vector>

#include "core/error.h"
#include "core/error_text.h"
#include "core/internal/mesh_builder.h"
#include "core/text_parsing.h"

namespace mmh::internal {
namespace {

namespace fs = std::filesystem;

// Largest MTL file read: material libraries are a few KB.
constexpr std::size_t kMaxMaterialFileBytes = std::size_t{16} << 20;

// The fields after the keyword joined by single spaces (a material or file name may hold spaces).
std::string RestOfLine(const std::vector<std::string_view>& fields) {
  std::string rest;
  for (std::size_t i = 1; i < fields.size(); ++i) {
    if (i > 1) rest += ' ';
    rest += fields[i];
  }
  return rest;
}

// Calls line(where, fields) for each line that is not blank or a comment ('#' to the end of the
// line), fields split on white space; where = "path:line".
template <typename LineFunction>
void ForEachStatement(std::string_view text, const std::string& path, LineFunction line) {
  std::size_t pos = 0;
  for (int number = 1; pos < text.size(); ++number) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view content = text.substr(pos, end - pos);
    pos = end + 1;
    content = content.substr(0, content.find('#'));
    const auto fields = SplitFields(content, " \t\r\f\v");
    if (!fields.empty()) line(path + ":" + std::to_string(number), fields);
  }
}

// The numbers after the statement's keyword; `counts` lists the numbers of values it may have.
std::vector<double> Numbers(const std::string& where, const std::vector<std::string_view>& fields,
                            std::initializer_list<std::size_t> counts, const char* layout) {
  bool count_ok = false;
  for (std::size_t count : counts) count_ok |= fields.size() == count + 1;
  if (!count_ok) {
    ThrowBadValue(where + ": " + std::string(fields[0]),
                  std::to_string(fields.size() - 1) + " values", layout);
  }
  std::vector<double> values(fields.size() - 1);
  for (std::size_t i = 1; i < fields.size(); ++i) {
    if (!ParseDouble(fields[i], &values[i - 1]) || !std::isfinite(values[i - 1])) {
      ThrowBadValue(where + ": " + std::string(fields[0]), Quote(fields[i]), "a finite number");
    }
  }
  return values;
}

// Kd of each material of an MTL file. A file that cannot be read gives none.
void ReadMaterials(const fs::path& path, std::map<std::string, Rgb8>* materials) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return;
  const std::string text = ReadTextFile(path, kMaxMaterialFileBytes);
  std::string current;
  ForEachStatement(text, path.string(), [&](const std::string& where, const auto& fields) {
    if (fields[0] == "newmtl") {
      current = RestOfLine(fields);
      (*materials)[current] = kDefaultMeshColor;
    } else if (fields[0] == "Kd" && materials->count(current)) {
      const auto rgb = Numbers(where, fields, {1, 3}, "'Kd r g b' (or 'Kd grey')");
      Rgb8& color = (*materials)[current];
      for (int c = 0; c < 3; ++c) color[c] = ColorByte(rgb[rgb.size() == 1 ? 0 : c]);
    }
  });
}

// A 1-based or negative OBJ index among `count` elements, as a 0-based index.
std::uint32_t ResolveIndex(std::string_view text, std::uint64_t count, const std::string& where,
                           const char* what) {
  std::int64_t index = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), index);
  const auto signed_count = static_cast<std::int64_t>(count);
  if (ec == std::errc() && end == text.data() + text.size() && index != 0 &&
      index <= signed_count && index >= -signed_count) {
    return static_cast<std::uint32_t>(index > 0 ? index - 1 : signed_count + index);
  }
  ThrowBadValue(where, std::string(what) + " index " + Quote(text),
                count == 0 ? std::string("a ") + what + " defined before it"
                           : "an index from 1 to " + std::to_string(count) + " or from -" +
                                 std::to_string(count) + " to -1");
}

}  // namespace

TriangleMesh ReadObjMesh(std::string_view text, const fs::path& path) {
  MeshBuilder builder(path.string());
  std::map<std::string, Rgb8> materials;
  Rgb8 material = kDefaultMeshColor;
  std::uint64_t texture_coordinates = 0;
  std::uint64_t normals = 0;
  std::vector<std::uint32_t> corners;
  ForEachStatement(text, path.string(), [&](const std::string& where, const auto& fields) {
    const std::string_view keyword = fields[0];
    if (keyword == "v") {
      const auto v = Numbers(where, fields, {3, 4, 6}, "'v x y z', 'v x y z w' or 'v x y z r g b'");
      if (v.size() == 6) {
        builder.AddVertex(v[0], v[1], v[2], {v[3], v[4], v[5]});
      } else if (v.size() == 4) {
        if (v[3] == 0) ThrowBadValue(where + ": v", "w = 0", "a non-zero weight w");
        builder.AddVertex(v[0] / v[3], v[1] / v[3], v[2] / v[3]);
      } else {
        builder.AddVertex(v[0], v[1], v[2]);
      }
    } else if (keyword == "vt") {
      Numbers(where, fields, {1, 2, 3}, "'vt u [v [w]]'");
      ++texture_coordinates;
    } else if (keyword == "vn") {
      Numbers(where, fields, {3}, "'vn x y z'");
      ++normals;
    } else if (keyword == "f") {
      if (fields.size() < 4) {
        ThrowBadValue(where + ": f", std::to_string(fields.size() - 1) + " corners",
                      "a face of at least 3 corners");
      }
      corners.clear();
      for (std::size_t i = 1; i < fields.size(); ++i) {
        const std::string_view corner = fields[i];
        const std::size_t slash1 = corner.find('/');
        const std::size_t slash2 =
            slash1 == std::string_view::npos ? slash1 : corner.find('/', slash1 + 1);
        const std::string at = where + ": f, corner " + std::to_string(i);
        if (slash2 != std::string_view::npos && corner.find('/', slash2 + 1) != corner.npos) {
          ThrowBadValue(at, Quote(corner), "'v', 'v/vt', 'v//vn' or 'v/vt/vn'");
        }
        corners.push_back(
            ResolveIndex(corner.substr(0, slash1), builder.vertex_count(), at, "vertex"));
        if (slash1 == corner.npos) continue;
        const std::string_view vt = corner.substr(
            slash1 + 1, slash2 == corner.npos ? corner.npos : slash2 - slash1 - 1);
        if (!vt.empty() || slash2 == corner.npos) {
          ResolveIndex(vt, texture_coordinates, at, "texture coordinate");
        }
        if (slash2 != corner.npos) {
          ResolveIndex(corner.substr(slash2 + 1), normals, at, "normal");
        }
      }
      builder.AddPolygon(corners, material);
    } else if (keyword == "mtllib") {
      // One or more file names; a name may hold spaces when it is the only one.
      const std::string whole = RestOfLine(fields);
      std::error_code ec;
      if (fs::is_regular_file(path.parent_path() / whole, ec)) {
        ReadMaterials(path.parent_path() / whole, &materials);
      } else {
        for (std::size_t i = 1; i < fields.size(); ++i) {
          ReadMaterials(path.parent_path() / std::string(fields[i]), &materials);
        }
      }
    } else if (keyword == "usemtl") {
      const auto found = materials.find(RestOfLine(fields));
      material = found == materials.end() ? kDefaultMeshColor : found->second;
    } else {
      const char first = keyword[0];
      const bool identifier = (first >= 'a' && first <= 'z') || (first >= 'A' && first <= 'Z') ||
                              first == '_';
      if (!identifier) {
        ThrowBadValue(where, Quote(keyword), "an OBJ statement (v, vt, vn, f, usemtl, ...)");
      }
      // Other statements (o, g, s, l, p, vp, curves and surfaces) do not make triangles.
    }
  });
  return builder.Build();
}

}  // namespace mmh::internal
