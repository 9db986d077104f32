#include "sim/duplo.h"

#include <algorithm>
#include <limits>
#include <map>
#include <tuple>

#include "core/config.h"
#include "core/error.h"
#include "core/options.h"
#include "sim/primitives.h"

namespace mmh::sim {
namespace {

constexpr DuploBrickType kBrickTypes[] = {
    {"1x1", 1, 1}, {"1x2", 1, 2}, {"1x3", 1, 3}, {"1x4", 1, 4}, {"2x2", 2, 2},
    {"2x3", 2, 3}, {"2x4", 2, 4}, {"2x6", 2, 6}, {"2x8", 2, 8}, {"4x4", 4, 4},
};

// Rebrickable's sRGB values of the LEGO colours Duplo bricks come in.
constexpr DuploColor kColors[] = {
    {"red", {201, 26, 9}},
    {"blue", {0, 85, 191}},
    {"yellow", {242, 205, 55}},
    {"green", kDuploGreen},
    {"bright_green", {75, 159, 74}},
    {"lime", {187, 233, 11}},
    {"white", {255, 255, 255}},
    {"black", {5, 19, 29}},
    {"orange", {254, 138, 24}},
    {"dark_blue", {10, 52, 99}},
    {"medium_blue", {90, 147, 219}},
    {"azure", {54, 174, 191}},
    {"light_gray", {160, 165, 169}},
    {"dark_gray", {108, 110, 104}},
    {"tan", {228, 205, 158}},
    {"reddish_brown", {88, 42, 18}},
    {"light_nougat", {246, 215, 179}},
    {"nougat", {208, 145, 104}},
    {"dark_red", {114, 14, 15}},
    {"pink", {228, 173, 200}},
    {"purple", {129, 0, 123}},
};

constexpr int kMaxGridCoordinate = 1000;
constexpr int kMaxLevel = 100;

// "where.key", or "file: key" when `where` ends with ':' (LoadDuploAssembly).
std::string Join(const std::string& where, const std::string& key) {
  if (where.empty()) return key;
  if (where.back() == ':') return where + " " + key;
  return where + "." + key;
}

std::string BrickWhere(const std::string& where, size_t index) {
  return Join(where, "bricks[" + std::to_string(index) + "]");
}

// A JSON value for a message, cut short if long.
std::string ShortDump(const nlohmann::json& value) {
  std::string text = value.dump();
  if (text.size() > 80) text = text.substr(0, 77) + "...";
  return text;
}

std::string Cell(int x, int y, int level) {
  return "[" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(level) + "]";
}

std::vector<std::string> TypeNames() {
  std::vector<std::string> names;
  for (const auto& type : kBrickTypes) names.emplace_back(type.name);
  return names;
}

std::vector<std::string> ColorNames() {
  std::vector<std::string> names;
  for (const auto& color : kColors) names.emplace_back(color.name);
  return names;
}

// The expectation for an unknown brick type, with a hint: "4x2" is "2x4" rotated.
std::string TypeExpectation(const std::string& unknown) {
  std::string expected = "a Duplo brick type, one of " + options_internal::JoinNames(TypeNames());
  const auto x = unknown.find('x');
  if (x != std::string::npos) {
    const std::string swapped = unknown.substr(x + 1) + "x" + unknown.substr(0, x);
    if (FindDuploBrickType(swapped)) {
      return expected + " (did you mean \"" + swapped + "\" with \"rotated\": true?)";
    }
  }
  const std::string suggestion = options_internal::SuggestName(unknown, TypeNames());
  if (!suggestion.empty()) expected += " (did you mean \"" + suggestion + "\"?)";
  return expected;
}

void CheckKeys(const nlohmann::json& object, const std::string& where,
               const std::vector<std::string>& known) {
  for (auto it = object.begin(); it != object.end(); ++it) {
    if (std::find(known.begin(), known.end(), it.key()) != known.end()) continue;
    const std::string suggestion = options_internal::SuggestName(it.key(), known);
    throw InputError(Join(where, it.key()) + ": key '" + it.key() + "' is unknown" +
                     (suggestion.empty() ? "" : " (did you mean '" + suggestion + "'?)") +
                     "; known keys here: " + options_internal::JoinNames(known));
  }
}

// An integer of a JSON value, or nullopt when it is not an integer within int range.
std::optional<int> AsInt(const nlohmann::json& value) {
  if (value.is_number_unsigned()) {
    const auto v = value.get<std::uint64_t>();
    if (v <= static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
      return static_cast<int>(v);
  } else if (value.is_number_integer()) {
    const auto v = value.get<std::int64_t>();
    if (v >= std::numeric_limits<int>::min() && v <= std::numeric_limits<int>::max()) {
      return static_cast<int>(v);
    }
  }
  return std::nullopt;
}

Rgb8 ParseColor(const nlohmann::json& value, const std::string& where) {
  const std::string expected = "a colour name (one of " +
                               options_internal::JoinNames(ColorNames()) +
                               ") or [r, g, b] with integers in [0, 255] (sRGB)";
  if (value.is_string()) {
    const std::string name = value.get<std::string>();
    if (auto color = FindDuploColor(name)) return *color;
    const std::string suggestion = options_internal::SuggestName(name, ColorNames());
    ThrowBadValue(where, ShortDump(value),
                  expected + (suggestion.empty() ? "" : " (did you mean \"" + suggestion + "\"?)"));
  }
  if (value.is_array() && value.size() == 3) {
    Rgb8 color;
    for (int k = 0; k < 3; ++k) {
      const auto channel = AsInt(value[k]);
      if (!channel || *channel < 0 || *channel > 255)
        ThrowBadValue(where, ShortDump(value), expected);
      color[k] = static_cast<uint8_t>(*channel);
    }
    return color;
  }
  ThrowBadValue(where, ShortDump(value), expected);
}

DuploBrick ParseBrick(const nlohmann::json& json, const std::string& where) {
  if (!json.is_object()) {
    ThrowBadValue(where, ShortDump(json),
                  "a brick {\"type\": \"2x4\", \"at\": [x, y, level], \"color\": \"red\"}");
  }
  CheckKeys(json, where, {"type", "at", "rotated", "color"});
  for (const char* required : {"type", "at", "color"}) {
    if (!json.contains(required)) {
      ThrowBadValue(Join(where, required), "nothing (the key is missing)",
                    std::string("the brick's ") + required);
    }
  }
  DuploBrick brick;
  const nlohmann::json& type = json.at("type");
  if (!type.is_string() || !FindDuploBrickType(type.get<std::string>())) {
    ThrowBadValue(Join(where, "type"), ShortDump(type),
                  TypeExpectation(type.is_string() ? type.get<std::string>() : ""));
  }
  brick.type = type.get<std::string>();

  const nlohmann::json& at = json.at("at");
  const std::string at_expected =
      "[x, y, level]: stud-grid integers with |x|, |y| <= " + std::to_string(kMaxGridCoordinate) +
      " and level in [0, " + std::to_string(kMaxLevel) + "]";
  if (!at.is_array() || at.size() != 3)
    ThrowBadValue(Join(where, "at"), ShortDump(at), at_expected);
  int* const targets[3] = {&brick.x, &brick.y, &brick.level};
  for (int k = 0; k < 3; ++k) {
    const auto v = AsInt(at[k]);
    if (!v) ThrowBadValue(Join(where, "at"), ShortDump(at), at_expected);
    *targets[k] = *v;
  }

  if (json.contains("rotated")) {
    const nlohmann::json& rotated = json.at("rotated");
    if (!rotated.is_boolean())
      ThrowBadValue(Join(where, "rotated"), ShortDump(rotated), "true or false");
    brick.rotated = rotated.get<bool>();
  }
  brick.color = ParseColor(json.at("color"), Join(where, "color"));
  return brick;
}

std::string ColorName(const Rgb8& color) {
  for (const auto& c : kColors) {
    if (c.rgb == color) return c.name;
  }
  return "";
}

}  // namespace

std::span<const DuploBrickType> DuploBrickTypes() { return kBrickTypes; }

std::optional<DuploBrickType> FindDuploBrickType(const std::string& name) {
  for (const auto& type : kBrickTypes) {
    if (name == type.name) return type;
  }
  return std::nullopt;
}

std::span<const DuploColor> DuploColors() { return kColors; }

std::optional<Rgb8> FindDuploColor(const std::string& name) {
  for (const auto& color : kColors) {
    if (name == color.name) return color.rgb;
  }
  return std::nullopt;
}

Eigen::Vector2i DuploFootprint(const DuploBrick& brick) {
  const auto type = FindDuploBrickType(brick.type);
  if (!type)
    ThrowBadValue("Duplo brick type", "\"" + brick.type + "\"", TypeExpectation(brick.type));
  return brick.rotated ? Eigen::Vector2i(type->studs_y, type->studs_x)
                       : Eigen::Vector2i(type->studs_x, type->studs_y);
}

DuploAssembly ParseDuploAssembly(const nlohmann::json& json, const std::string& where) {
  if (!json.is_object()) {
    ThrowBadValue(where.empty() ? "(top level)" : where, ShortDump(json),
                  "a Duplo assembly, an object {\"bricks\": [...]}");
  }
  CheckKeys(json, where, {"name", "description", "bricks"});
  DuploAssembly assembly;
  for (const char* key : {"name", "description"}) {
    if (!json.contains(key)) continue;
    if (!json.at(key).is_string())
      ThrowBadValue(Join(where, key), ShortDump(json.at(key)), "a string");
    (std::string(key) == "name" ? assembly.name : assembly.description) =
        json.at(key).get<std::string>();
  }
  if (!json.contains("bricks")) {
    ThrowBadValue(Join(where, "bricks"), "nothing (the key is missing)", "a list of bricks");
  }
  const nlohmann::json& bricks = json.at("bricks");
  if (!bricks.is_array() || bricks.empty()) {
    ThrowBadValue(Join(where, "bricks"), ShortDump(bricks), "a non-empty list of bricks");
  }
  for (size_t i = 0; i < bricks.size(); ++i) {
    assembly.bricks.push_back(ParseBrick(bricks[i], BrickWhere(where, i)));
  }
  ValidateDuploAssembly(assembly, where);
  return assembly;
}

DuploAssembly LoadDuploAssembly(const std::filesystem::path& path) {
  const Config config = Config::Load(path);
  return ParseDuploAssembly(config.root(), path.string() + ":");
}

nlohmann::json DuploAssemblyToJson(const DuploAssembly& assembly) {
  nlohmann::json json = nlohmann::json::object();
  if (!assembly.name.empty()) json["name"] = assembly.name;
  if (!assembly.description.empty()) json["description"] = assembly.description;
  json["bricks"] = nlohmann::json::array();
  for (const DuploBrick& brick : assembly.bricks) {
    nlohmann::json b = nlohmann::json::object();
    b["type"] = brick.type;
    b["at"] = {brick.x, brick.y, brick.level};
    b["rotated"] = brick.rotated;
    const std::string color = ColorName(brick.color);
    if (color.empty()) {
      b["color"] = {brick.color[0], brick.color[1], brick.color[2]};
    } else {
      b["color"] = color;
    }
    json["bricks"].push_back(b);
  }
  return json;
}

void ValidateDuploAssembly(const DuploAssembly& assembly, const std::string& where) {
  if (assembly.bricks.empty()) {
    ThrowBadValue(Join(where, "bricks"), "[]", "a non-empty list of bricks");
  }
  // Cell (x, y, level) -> index of the brick occupying it.
  std::map<std::tuple<int, int, int>, size_t> occupied;
  for (size_t i = 0; i < assembly.bricks.size(); ++i) {
    const DuploBrick& brick = assembly.bricks[i];
    if (!FindDuploBrickType(brick.type)) {
      ThrowBadValue(Join(BrickWhere(where, i), "type"), "\"" + brick.type + "\"",
                    TypeExpectation(brick.type));
    }
    if (std::abs(brick.x) > kMaxGridCoordinate || std::abs(brick.y) > kMaxGridCoordinate ||
        brick.level < 0 || brick.level > kMaxLevel) {
      ThrowBadValue(Join(BrickWhere(where, i), "at"), Cell(brick.x, brick.y, brick.level),
                    "stud-grid integers with |x|, |y| <= " + std::to_string(kMaxGridCoordinate) +
                        " and level in [0, " + std::to_string(kMaxLevel) + "]");
    }
    const Eigen::Vector2i footprint = DuploFootprint(brick);
    for (int dx = 0; dx < footprint.x(); ++dx) {
      for (int dy = 0; dy < footprint.y(); ++dy) {
        const auto cell = std::make_tuple(brick.x + dx, brick.y + dy, brick.level);
        const auto [it, inserted] = occupied.emplace(cell, i);
        if (!inserted) {
          ThrowBadValue(BrickWhere(where, i),
                        "a " + brick.type + " brick at " + Cell(brick.x, brick.y, brick.level) +
                            " sharing cell " + Cell(brick.x + dx, brick.y + dy, brick.level) +
                            " with bricks[" + std::to_string(it->second) + "]",
                        "bricks that occupy distinct stud cells");
        }
      }
    }
  }
  for (size_t i = 0; i < assembly.bricks.size(); ++i) {
    const DuploBrick& brick = assembly.bricks[i];
    if (brick.level == 0) continue;
    const Eigen::Vector2i footprint = DuploFootprint(brick);
    bool supported = false;
    for (int dx = 0; dx < footprint.x() && !supported; ++dx) {
      for (int dy = 0; dy < footprint.y() && !supported; ++dy) {
        supported = occupied.count({brick.x + dx, brick.y + dy, brick.level - 1}) > 0;
      }
    }
    if (!supported) {
      ThrowBadValue(BrickWhere(where, i),
                    "a " + brick.type + " brick at " + Cell(brick.x, brick.y, brick.level) +
                        " with nothing beneath it in layer " + std::to_string(brick.level - 1),
                    "every brick above layer 0 to rest on at least one brick of the layer below");
    }
  }
}

TriangleMesh BuildDuploMesh(const DuploAssembly& assembly, int stud_segments) {
  ValidateDuploAssembly(assembly,
                        "assembly" + (assembly.name.empty() ? "" : " '" + assembly.name + "'"));
  std::map<std::tuple<int, int, int>, size_t> occupied;
  Eigen::Vector2i min_cell = Eigen::Vector2i::Constant(std::numeric_limits<int>::max());
  Eigen::Vector2i max_cell = Eigen::Vector2i::Constant(std::numeric_limits<int>::min());
  for (size_t i = 0; i < assembly.bricks.size(); ++i) {
    const DuploBrick& brick = assembly.bricks[i];
    const Eigen::Vector2i footprint = DuploFootprint(brick);
    min_cell = min_cell.cwiseMin(Eigen::Vector2i(brick.x, brick.y));
    max_cell =
        max_cell.cwiseMax(Eigen::Vector2i(brick.x, brick.y) + footprint - Eigen::Vector2i::Ones());
    for (int dx = 0; dx < footprint.x(); ++dx) {
      for (int dy = 0; dy < footprint.y(); ++dy) {
        occupied.emplace(std::make_tuple(brick.x + dx, brick.y + dy, brick.level), i);
      }
    }
  }
  // Cell (i, j) has its stud at (i, j) * pitch before centring; the footprint's bounding box is
  // symmetric about the mean of its extreme cells.
  const Eigen::Vector2d centre = 0.5 * kDuploPitch * (min_cell + max_cell).cast<double>();

  TriangleMesh mesh;
  for (const DuploBrick& brick : assembly.bricks) {
    const Eigen::Vector2i footprint = DuploFootprint(brick);
    const Eigen::Vector2d low = kDuploPitch * Eigen::Vector2d(brick.x - 0.5, brick.y - 0.5) +
                                Eigen::Vector2d::Constant(0.5 * kDuploClearance) - centre;
    const Eigen::Vector2d high =
        low + kDuploPitch * footprint.cast<double>() - Eigen::Vector2d::Constant(kDuploClearance);
    const double bottom = brick.level * kDuploBrickHeight;
    const double top = bottom + kDuploBrickHeight;
    AppendMesh(MakeBoxBetween({low.x(), low.y(), bottom}, {high.x(), high.y(), top}, brick.color),
               Rigid3::Identity(), &mesh);
    const TriangleMesh stud =
        MakeCylinder(0.5 * kDuploStudDiameter, kDuploStudHeight, stud_segments, brick.color);
    for (int dx = 0; dx < footprint.x(); ++dx) {
      for (int dy = 0; dy < footprint.y(); ++dy) {
        if (occupied.count({brick.x + dx, brick.y + dy, brick.level + 1})) continue;  // hidden
        const Eigen::Vector2d at =
            kDuploPitch * Eigen::Vector2d(brick.x + dx, brick.y + dy) - centre;
        AppendMesh(stud, Rigid3(Eigen::Quaterniond::Identity(), {at.x(), at.y(), top}), &mesh);
      }
    }
  }
  return mesh;
}

TriangleMesh MakeDuploBrick(const std::string& type, const Rgb8& color, int stud_segments) {
  DuploAssembly assembly;
  assembly.name = type + " brick";
  DuploBrick brick;
  brick.type = type;
  brick.color = color;
  assembly.bricks.push_back(brick);
  return BuildDuploMesh(assembly, stud_segments);
}

DuploAssembly SoldierProxy() {
  auto brick = [](const char* type, int x, int y, int level, bool rotated, const char* color) {
    return DuploBrick{type, x, y, level, rotated, *FindDuploColor(color)};
  };
  DuploAssembly soldier;
  soldier.name = "soldier";
  soldier.description =
      "The soldier of the paper's 'Soldier takes a Break' story: boots, trousers, tunic, head with "
      "a busby, and a rifle on his left (+x). Faces -y.";
  soldier.bricks = {
      brick("2x4", 0, 0, 0, true, "black"),           // boots
      brick("2x4", 0, 0, 1, true, "dark_blue"),       // trousers
      brick("2x4", 0, 0, 2, true, "red"),             // tunic
      brick("2x2", 1, 0, 3, false, "light_nougat"),   // head
      brick("1x2", 3, 0, 3, false, "reddish_brown"),  // rifle
      brick("2x2", 1, 0, 4, false, "black"),          // busby
  };
  return soldier;
}

}  // namespace mmh::sim
