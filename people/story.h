// A story is data (configs/stories/*.json): for each object, the path it follows over the table
// and the script's beats with their meaning and nominal timing. Animators (people/performance.h)
// act it out; the latent quality of a take is measured against it.
//
// File format (every key checked; unknown keys are errors):
//   {
//     "name": "Soldier takes a Break",
//     "script": "A soldier is guarding a castle ...",        (the paper's text)
//     "objects": [
//       {
//         "name": "soldier",
//         "proxy": "../proxies/soldier.json",                (relative to the story file)
//         "height": 0.08,                                     [m] top of the figure above its base
//         "path": [[x, y], ...],                              [m] waypoints, table frame
//         "start": 0,                                         waypoint the object starts at
//         "end": 60.0,                                        [s] nominal end of the last beat
//         "beats": [
//           {"kind": "march", "start": 0.0, "to": 1, "meaning": "guarding the castle"},
//           {"kind": "look_around", "start": 12.0, "meaning": "is anybody watching?"},
//           {"kind": "stroll", "start": 15.0, "to": 4, "intensity": 1.0, "intensity_end": 1.8},
//           {"kind": "hit", "start": 20.0, "to": 2, "target": "monster"}, ...
//         ]
//       }
//     ]
//   }
// Beat times are nominal seconds from the take's start: strictly increasing, the first at 0, each
// beat lasting until the next one starts (the last until "end"). Travelling beats ("to" required)
// move the object along the path's waypoints from where it stands to waypoint "to"; the others
// ("to" forbidden) happen in place. Objects are listed in recording order: a layered object's
// "hit" beat targets an object listed before it.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/table_setup.h"

namespace mmh::people {

enum class BeatKind {
  kStand,       // standing still
  kWalk,        // walking: steps with a small bounce
  kMarch,       // marching: brisk, higher steps
  kStroll,      // casual stroll: slower steps, side-to-side sway that grows with intensity
  kLimp,        // limping: every other step short and low, tilted
  kJump,        // jumping with joy: hops while travelling
  kSlip,        // slipping on a banana peel: a fast slide, tilting backwards
  kFall,        // falling down onto the back
  kLie,         // lying on the ground
  kGetUp,       // getting up, slowly and with effort
  kLookAround,  // looking around: head turns as yaw swings
  kTurn,        // turning in place towards the next travelling beat
  kHit,         // jumping onto the target object's head (layered stories)
};
std::span<const std::pair<BeatKind, const char*>> EnumNames(BeatKind);
const char* BeatKindName(BeatKind kind);
// Whether the beat moves the object along the path ("to" required).
bool Travels(BeatKind kind);

// What the script asks of a beat: the motion's characteristic features, per unit intensity.
// These are the targets a performance is judged against (people/take_quality.h).
struct BeatStyleTarget {
  double step_rate = 0.0;  // [1/s] steps (or hops) per second; 0: none
  double bounce = 0.0;     // [m] height of a step's (or hop's) rise
  double sway = 0.0;       // [rad] side-to-side tilt amplitude (stroll, limp)
  double yaw_swing = 0.0;  // [rad] head-turn amplitude (look_around)
  double tilt = 0.0;       // [rad] tilt from upright reached at the beat's end (fall, slip, lie)
};
BeatStyleTarget ScriptTarget(BeatKind kind);

struct Beat {
  BeatKind kind = BeatKind::kStand;
  double start = 0.0;        // [s] nominal start
  int to = -1;               // waypoint reached at the end (travelling beats), else -1
  double intensity = 1.0;    // multiplies the style target at the beat's start
  double intensity_end = 1;  // ... and at its end (linear in between)
  std::string target;        // hit: the object whose head is hit
  std::string meaning;       // the script's words for this beat

  // Intensity at progress u of the beat (0 at its start, 1 at its end; clamped).
  double IntensityAt(double u) const;
};

struct StoryObject {
  std::string name;
  std::string proxy;                  // proxy model (configs/proxies/*.json, .obj or .ply)
  double height = 0.08;               // [m] of the figure (a hit lands on the target's top)
  std::vector<Eigen::Vector2d> path;  // waypoints [m], table frame
  int start_waypoint = 0;
  double end = 0.0;  // [s] nominal end
  std::vector<Beat> beats;

  // Nominal duration of beat i [s].
  double BeatDuration(int i) const;
  // The points a travelling beat passes: from the waypoint it starts at to its "to" (inclusive),
  // in order (indices may run backwards). In-place beats: the single point where they happen.
  std::vector<Eigen::Vector2d> BeatPolyline(int i) const;
  // Waypoint the object stands at when beat i starts.
  int WaypointAtStart(int i) const;
};

struct Story {
  std::string name;
  std::string script;
  std::string file;  // where it was read from (for messages)
  std::vector<StoryObject> objects;

  // Index of the object with this name, or -1.
  int ObjectIndex(const std::string& name) const;
};

// Reads and validates a story; every error names the file, the object and the beat, the value and
// what was expected. Paths must lie inside the play area of `table` (the default setup unless
// given).
Story LoadStory(const std::filesystem::path& file, const TableSetup& table = {});
// The same from JSON text (`file` names it in messages).
Story ParseStory(const std::string& text, const std::string& file, const TableSetup& table = {});

// Polyline helpers (points in order).
double PolylineLength(std::span<const Eigen::Vector2d> points);
// Point at arc length s (clamped) and the unit tangent there.
Eigen::Vector2d PolylinePoint(std::span<const Eigen::Vector2d> points, double s,
                              Eigen::Vector2d* tangent = nullptr);
// Distance from p to the polyline.
double DistanceToPolyline(std::span<const Eigen::Vector2d> points, const Eigen::Vector2d& p);

}  // namespace mmh::people
