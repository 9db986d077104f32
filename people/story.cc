#include "people/story.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>

#include "core/error.h"
#include "core/json_text.h"
#include "core/options.h"
#include "core/text_parsing.h"

namespace mmh::people {
namespace {

constexpr std::pair<BeatKind, const char*> kBeatKindNames[] = {
    {BeatKind::kStand, "stand"},
    {BeatKind::kWalk, "walk"},
    {BeatKind::kMarch, "march"},
    {BeatKind::kStroll, "stroll"},
    {BeatKind::kLimp, "limp"},
    {BeatKind::kJump, "jump"},
    {BeatKind::kSlip, "slip"},
    {BeatKind::kFall, "fall"},
    {BeatKind::kLie, "lie"},
    {BeatKind::kGetUp, "get_up"},
    {BeatKind::kLookAround, "look_around"},
    {BeatKind::kTurn, "turn"},
    {BeatKind::kHit, "hit"},
};

// Rejects keys of `object` not in `known`, naming `where` and suggesting the closest name.
void RequireKnownKeys(const nlohmann::json& object, const std::vector<std::string>& known,
                      const std::string& where) {
  for (auto it = object.begin(); it != object.end(); ++it) {
    if (std::find(known.begin(), known.end(), it.key()) != known.end()) continue;
    const std::string suggestion = options_internal::SuggestName(it.key(), known);
    ThrowBadValue(where + "." + it.key(), "an unknown key",
                  "one of " + options_internal::JoinNames(known) +
                      (suggestion.empty() ? "" : " (did you mean \"" + suggestion + "\"?)"));
  }
}

double GetNumber(const nlohmann::json& object, const char* key, const std::string& where,
                 double fallback, bool required) {
  const auto it = object.find(key);
  if (it == object.end()) {
    if (required) ThrowBadValue(where + "." + key, "nothing", "a number");
    return fallback;
  }
  if (!it->is_number() || !std::isfinite(it->get<double>())) {
    ThrowBadValue(where + "." + key, it->dump(), "a finite number");
  }
  return it->get<double>();
}

int GetInt(const nlohmann::json& object, const char* key, const std::string& where, int fallback,
           bool required) {
  const auto it = object.find(key);
  if (it == object.end()) {
    if (required) ThrowBadValue(where + "." + key, "nothing", "an integer");
    return fallback;
  }
  if (!it->is_number_integer() || std::abs(it->get<std::int64_t>()) > 1000000) {
    ThrowBadValue(where + "." + key, it->dump(), "an integer");
  }
  return static_cast<int>(it->get<std::int64_t>());
}

std::string GetString(const nlohmann::json& object, const char* key, const std::string& where,
                      bool required) {
  const auto it = object.find(key);
  if (it == object.end()) {
    if (required) ThrowBadValue(where + "." + key, "nothing", "a string");
    return "";
  }
  if (!it->is_string()) ThrowBadValue(where + "." + key, it->dump(), "a string");
  return it->get<std::string>();
}

BeatKind ParseKind(const nlohmann::json& value, const std::string& where) {
  std::vector<std::string> names;
  for (const auto& [kind, name] : kBeatKindNames) names.emplace_back(name);
  if (value.is_string()) {
    for (const auto& [kind, name] : kBeatKindNames) {
      if (value.get<std::string>() == name) return kind;
    }
    const std::string suggestion = options_internal::SuggestName(value.get<std::string>(), names);
    ThrowBadValue(where, value.dump(),
                  "a beat kind: one of " + options_internal::JoinNames(names) +
                      (suggestion.empty() ? "" : " (did you mean \"" + suggestion + "\"?)"));
  }
  ThrowBadValue(where, value.dump(), "a beat kind (a string)");
}

StoryObject ParseObject(const nlohmann::json& json, const std::string& where,
                        const TableSetup& table) {
  if (!json.is_object()) ThrowBadValue(where, json.dump(), "an object");
  RequireKnownKeys(json, {"name", "proxy", "height", "path", "start", "end", "beats"}, where);
  StoryObject object;
  object.name = GetString(json, "name", where, true);
  if (object.name.empty()) ThrowBadValue(where + ".name", "\"\"", "a non-empty name");
  object.proxy = GetString(json, "proxy", where, false);
  object.height = GetNumber(json, "height", where, object.height, false);
  if (object.height <= 0.0 || object.height > 0.5) {
    ThrowBadValue(where + ".height", FormatNumber(object.height), "a height in (0, 0.5] m");
  }

  const auto path = json.find("path");
  if (path == json.end() || !path->is_array() || path->empty()) {
    ThrowBadValue(where + ".path", path == json.end() ? "nothing" : path->dump(),
                  "a non-empty list of [x, y] waypoints in metres");
  }
  const double half_width = 0.5 * table.play_area_width;
  const double half_depth = 0.5 * table.play_area_depth;
  for (std::size_t k = 0; k < path->size(); ++k) {
    const nlohmann::json& p = (*path)[k];
    const std::string at = where + ".path[" + std::to_string(k) + "]";
    if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number()) {
      ThrowBadValue(at, p.dump(), "[x, y] in metres");
    }
    const Eigen::Vector2d point(p[0].get<double>(), p[1].get<double>());
    if (!point.allFinite()) ThrowBadValue(at, p.dump(), "finite coordinates");
    // The story happens in the play area; a path that leaves it (or the table) cannot be tracked.
    if (std::abs(point.x()) > half_width || std::abs(point.y()) > half_depth) {
      ThrowBadValue(at, p.dump(),
                    "a waypoint inside the play area (|x| <= " + FormatNumber(half_width) +
                        " m, |y| <= " + FormatNumber(half_depth) + " m, table frame)");
    }
    object.path.push_back(point);
  }
  const int waypoints = static_cast<int>(object.path.size());
  object.start_waypoint = GetInt(json, "start", where, 0, false);
  if (object.start_waypoint < 0 || object.start_waypoint >= waypoints) {
    ThrowBadValue(where + ".start", std::to_string(object.start_waypoint),
                  "a waypoint index in [0, " + std::to_string(waypoints - 1) + "]");
  }

  const auto beats = json.find("beats");
  if (beats == json.end() || !beats->is_array() || beats->empty()) {
    ThrowBadValue(where + ".beats", beats == json.end() ? "nothing" : beats->dump(),
                  "a non-empty list of beats");
  }
  int at_waypoint = object.start_waypoint;
  for (std::size_t i = 0; i < beats->size(); ++i) {
    const nlohmann::json& b = (*beats)[i];
    const std::string at = where + ".beats[" + std::to_string(i) + "]";
    if (!b.is_object()) ThrowBadValue(at, b.dump(), "a beat object");
    RequireKnownKeys(b, {"kind", "start", "to", "intensity", "intensity_end", "target", "meaning"},
                     at);
    Beat beat;
    const auto kind = b.find("kind");
    if (kind == b.end()) ThrowBadValue(at + ".kind", "nothing", "a beat kind");
    beat.kind = ParseKind(*kind, at + ".kind");
    beat.start = GetNumber(b, "start", at, 0.0, true);
    if (i == 0 && beat.start != 0.0) {
      ThrowBadValue(at + ".start", FormatNumber(beat.start), "0 (the first beat starts the take)");
    }
    if (i > 0 && !(beat.start > object.beats.back().start)) {
      ThrowBadValue(at + ".start", FormatNumber(beat.start),
                    "a time after the previous beat's start (" +
                        FormatNumber(object.beats.back().start) + " s): beat times must increase");
    }
    beat.intensity = GetNumber(b, "intensity", at, 1.0, false);
    beat.intensity_end = GetNumber(b, "intensity_end", at, beat.intensity, false);
    for (const double value : {beat.intensity, beat.intensity_end}) {
      if (value < 0.0 || value > 3.0) {
        ThrowBadValue(at + ".intensity", FormatNumber(value), "an intensity in [0, 3]");
      }
    }
    beat.meaning = GetString(b, "meaning", at, false);
    beat.target = GetString(b, "target", at, false);
    if (Travels(beat.kind)) {
      beat.to = GetInt(b, "to", at, -1, true);
      if (beat.to < 0 || beat.to >= waypoints) {
        ThrowBadValue(at + ".to", std::to_string(beat.to),
                      "a waypoint index in [0, " + std::to_string(waypoints - 1) + "]");
      }
      if (beat.to == at_waypoint) {
        ThrowBadValue(at + ".to", std::to_string(beat.to),
                      "a waypoint other than the one the object stands at (" +
                          std::to_string(at_waypoint) + ")");
      }
      at_waypoint = beat.to;
    } else if (b.contains("to")) {
      ThrowBadValue(
          at + ".to", b["to"].dump(),
          std::string("no \"to\": a \"") + BeatKindName(beat.kind) + "\" beat happens in place");
    }
    if (beat.kind == BeatKind::kHit && beat.target.empty()) {
      ThrowBadValue(at + ".target", "nothing", "the name of the object whose head is hit");
    }
    if (beat.kind != BeatKind::kHit && !beat.target.empty()) {
      ThrowBadValue(at + ".target", "\"" + beat.target + "\"", "no target (only \"hit\" beats)");
    }
    object.beats.push_back(beat);
  }
  object.end = GetNumber(json, "end", where, 0.0, true);
  if (!(object.end > object.beats.back().start)) {
    ThrowBadValue(
        where + ".end", FormatNumber(object.end),
        "a time after the last beat's start (" + FormatNumber(object.beats.back().start) + " s)");
  }
  if (object.end > 3600.0) {
    ThrowBadValue(where + ".end", FormatNumber(object.end), "at most 3600 s");
  }
  return object;
}

}  // namespace

std::span<const std::pair<BeatKind, const char*>> EnumNames(BeatKind) { return kBeatKindNames; }

const char* BeatKindName(BeatKind kind) {
  for (const auto& [k, name] : kBeatKindNames) {
    if (k == kind) return name;
  }
  return "?";
}

bool Travels(BeatKind kind) {
  switch (kind) {
    case BeatKind::kWalk:
    case BeatKind::kMarch:
    case BeatKind::kStroll:
    case BeatKind::kLimp:
    case BeatKind::kJump:
    case BeatKind::kSlip:
    case BeatKind::kHit:
      return true;
    default:
      return false;
  }
}

BeatStyleTarget ScriptTarget(BeatKind kind) {
  BeatStyleTarget t;
  switch (kind) {
    case BeatKind::kWalk:
      t.step_rate = 2.0, t.bounce = 0.008;
      break;
    case BeatKind::kMarch:
      t.step_rate = 2.4, t.bounce = 0.014;
      break;
    case BeatKind::kStroll:
      t.step_rate = 1.6, t.bounce = 0.007, t.sway = 0.10;
      break;
    case BeatKind::kLimp:
      t.step_rate = 1.5, t.bounce = 0.010, t.sway = 0.14;
      break;
    case BeatKind::kJump:
      t.step_rate = 1.5, t.bounce = 0.040;
      break;
    case BeatKind::kSlip:
      t.tilt = 0.45;
      break;
    case BeatKind::kFall:
    case BeatKind::kLie:
      t.tilt = std::numbers::pi / 2;
      break;
    case BeatKind::kLookAround:
      t.yaw_swing = 0.9;
      break;
    case BeatKind::kHit:
      t.step_rate = 2.0, t.bounce = 0.010;
      break;
    case BeatKind::kStand:
    case BeatKind::kGetUp:
    case BeatKind::kTurn:
      break;
  }
  return t;
}

double Beat::IntensityAt(double u) const {
  return intensity + (intensity_end - intensity) * std::clamp(u, 0.0, 1.0);
}

double StoryObject::BeatDuration(int i) const {
  const double next = i + 1 < static_cast<int>(beats.size()) ? beats[i + 1].start : end;
  return next - beats[i].start;
}

int StoryObject::WaypointAtStart(int i) const {
  int at = start_waypoint;
  for (int k = 0; k < i; ++k) {
    if (beats[k].to >= 0) at = beats[k].to;
  }
  return at;
}

std::vector<Eigen::Vector2d> StoryObject::BeatPolyline(int i) const {
  const int from = WaypointAtStart(i);
  if (beats[i].to < 0) return {path[from]};
  std::vector<Eigen::Vector2d> points;
  const int step = beats[i].to > from ? 1 : -1;
  for (int k = from;; k += step) {
    points.push_back(path[k]);
    if (k == beats[i].to) break;
  }
  return points;
}

int Story::ObjectIndex(const std::string& name) const {
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (objects[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

Story ParseStory(const std::string& text, const std::string& file, const TableSetup& table) {
  const nlohmann::json json = ParseJsonText(text, file);
  if (!json.is_object()) ThrowBadValue(file, "not an object", "a story object");
  RequireKnownKeys(json, {"name", "script", "objects"}, file);
  Story story;
  story.file = file;
  story.name = GetString(json, "name", file, true);
  story.script = GetString(json, "script", file, false);
  const auto objects = json.find("objects");
  if (objects == json.end() || !objects->is_array() || objects->empty()) {
    ThrowBadValue(file + ": objects", objects == json.end() ? "nothing" : objects->dump(),
                  "a non-empty list of objects");
  }
  for (std::size_t k = 0; k < objects->size(); ++k) {
    const std::string where = file + ": objects[" + std::to_string(k) + "]";
    StoryObject object = ParseObject((*objects)[k], where, table);
    if (story.ObjectIndex(object.name) >= 0) {
      ThrowBadValue(where + ".name", "\"" + object.name + "\"", "a name not used before");
    }
    for (std::size_t i = 0; i < object.beats.size(); ++i) {
      const std::string& target = object.beats[i].target;
      if (target.empty()) continue;
      // A layered object is recorded while the earlier objects' montages play.
      if (story.ObjectIndex(target) < 0) {
        ThrowBadValue(where + ".beats[" + std::to_string(i) + "].target", "\"" + target + "\"",
                      "an object listed before \"" + object.name + "\"");
      }
    }
    story.objects.push_back(std::move(object));
  }
  return story;
}

Story LoadStory(const std::filesystem::path& file, const TableSetup& table) {
  return ParseStory(ReadTextFile(file), file.string(), table);
}

double PolylineLength(std::span<const Eigen::Vector2d> points) {
  double length = 0.0;
  for (std::size_t k = 1; k < points.size(); ++k) length += (points[k] - points[k - 1]).norm();
  return length;
}

Eigen::Vector2d PolylinePoint(std::span<const Eigen::Vector2d> points, double s,
                              Eigen::Vector2d* tangent) {
  if (tangent) *tangent = Eigen::Vector2d::Zero();
  if (points.size() < 2) return points.empty() ? Eigen::Vector2d::Zero() : points[0];
  s = std::max(s, 0.0);
  for (std::size_t k = 1; k < points.size(); ++k) {
    const Eigen::Vector2d d = points[k] - points[k - 1];
    const double length = d.norm();
    if (length <= 0.0) continue;
    if (s <= length || k + 1 == points.size()) {
      if (tangent) *tangent = d / length;
      return points[k - 1] + d * std::min(s / length, 1.0);
    }
    s -= length;
  }
  return points.back();
}

double DistanceToPolyline(std::span<const Eigen::Vector2d> points, const Eigen::Vector2d& p) {
  if (points.empty()) return std::numeric_limits<double>::infinity();
  double best = (p - points[0]).norm();
  for (std::size_t k = 1; k < points.size(); ++k) {
    const Eigen::Vector2d d = points[k] - points[k - 1];
    const double length2 = d.squaredNorm();
    const double u = length2 > 0 ? std::clamp((p - points[k - 1]).dot(d) / length2, 0.0, 1.0) : 0.0;
    best = std::min(best, (p - (points[k - 1] + u * d)).norm());
  }
  return best;
}

}  // namespace mmh::people
