// The static table-top scene (table, floor, wall, the play area and Like box marked with tape, an
// optional Duplo castle), the slider block's pose in the Like box, and the animator's hand.
//
// Table frame (docs/notation.md): z up, origin at the centre of the play area on the table top,
// x to the right as seen by the camera, y away from the camera. The camera stands above and in
// front of the table, by default at (0, -0.65, 0.55), 0.85 m from the origin it looks at; the
// animator sits behind the table (+y) facing it.
#pragma once

#include <Eigen/Core>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/rigid3.h"
#include "core/table_setup.h"
#include "core/triangle_mesh.h"
#include "sim/materials.h"

namespace mmh::sim {

struct NamedMesh {
  std::string name;
  TriangleMesh mesh;
};

// Scenery on the table behind the play area (the paper's stories play in front of Duplo scenery).
enum class TableProps {
  kNone,
  // A Duplo-style castle 0.30 m wide, 0.16 m deep and 0.26 m tall (flag included): four walls with
  // crenellations, a gate with a recessed door facing the camera, four square towers with
  // crenellations and a flag; its front 4 cm behind the play area.
  kCastle,
};
std::span<const std::pair<TableProps, const char*>> EnumNames(TableProps);

// A static object of the user's on or around the table (config `scene.objects`): a mesh file placed
// by table_T_object, e.g. the other objects of a real recording's view (docs/sensor.md, "At a
// glance"). The pose is a translation [m] and a unit quaternion (x, y, z, w as in TUM files).
struct SceneObject {
  std::string name;    // unique, and none of the scene's own objects' names (BuildTableScene)
  std::string mesh;    // an OBJ or PLY file, or a Duplo assembly (.json), as render.proxy
  double scale = 1.0;  // applied to the file's vertex positions (0.001 for millimetres)
  double x = 0.0, y = 0.0, z = 0.0;
  double qx = 0.0, qy = 0.0, qz = 0.0, qw = 1.0;  // norm within 1e-3 of 1; normalised on use
  SurfaceMaterial material{0.5, 0.0};

  template <class V>
  void VisitFields(V& v) {
    v("name", name);
    v("mesh", mesh);
    v("scale", scale);
    v("x", x);
    v("y", y);
    v("z", z);
    v("qx", qx);
    v("qy", qy);
    v("qz", qz);
    v("qw", qw);
    v("material", material);
  }
  void Validate(const std::string& prefix) const;
  Rigid3 TableTObject() const;
};

// The table's calibration (core/table_setup.h: play area, Like box, slider block) and the furniture
// around it. The slider block's size is not a config key: the scene's block is a 2x2 Duplo brick
// (kSliderBlockSize).
struct TableSceneOptions : TableSetup {
  // Table top [m]: width along its x, depth along its y, its top at z = 0.
  double table_width = 1.2;
  double table_depth = 0.8;
  double table_thickness = 0.03;
  // Table top above the floor [m] (legs 5 cm square at the corners; the floor is at -height).
  double table_height = 0.75;
  // The table top's centre [m] and its turn about z [deg] in the table frame: by default centred
  // on the play area and square to it; a real scene's desk where its edges are (the real views
  // of tests/data/real/ycbv/views, docs/sensor.md).
  double table_x = 0.0;
  double table_y = 0.0;
  double table_yaw_deg = 0.0;
  // Tape [m]: laid outside the rectangles' edges (their insides keep their full size), 1 mm
  // thick; thickness 0: no tape (a real scene's view).
  double tape_width = 0.006;
  double tape_thickness = 0.001;
  // A wall behind the table (y = backdrop_y, facing the camera) from the floor up to 1.25 m above
  // the table, 3 m wide; without it the far background is out of the Kinect's range.
  bool backdrop = true;
  double backdrop_y = 0.5;  // [m], at least table_depth / 2
  TableProps props = TableProps::kNone;
  // Materials in the IR band (the structured-light sensor mode).
  SceneMaterials materials;
  // The user's static objects (none by default); loaded by LoadSceneObjects.
  std::vector<SceneObject> objects;

  template <class V>
  void VisitFields(V& v) {
    v("table_width", table_width);
    v("table_depth", table_depth);
    v("table_thickness", table_thickness);
    v("table_height", table_height);
    v("table_x", table_x);
    v("table_y", table_y);
    v("table_yaw_deg", table_yaw_deg);
    v("play_area_width", play_area_width);
    v("play_area_depth", play_area_depth);
    v("like_box_center_x", like_box_center_x);
    v("like_box_center_y", like_box_center_y);
    v("like_box_length", like_box_length);
    v("like_box_width", like_box_width);
    v("tape_width", tape_width);
    v("tape_thickness", tape_thickness);
    v("backdrop", backdrop);
    v("backdrop_y", backdrop_y);
    v("props", props);
    v("materials", materials);
    v("objects", objects);
  }
  // Positive finite sizes; the play area, the Like box (with its tape) and the castle on the table;
  // the Like box apart from the play area and longer than the slider block; the wall behind the
  // table. InputErrors name prefix + field.
  void Validate(const std::string& prefix) const;
  // table_T_top: the table top's own frame (centred, x along its width) in the table frame.
  Rigid3 TableTTop() const;
};

// Colours of the scene [sRGB].
inline constexpr Rgb8 kTableColor = {164, 116, 73};        // oak-like wood
inline constexpr Rgb8 kPlayAreaTapeColor = {30, 90, 200};  // blue tape
inline constexpr Rgb8 kLikeBoxTapeColor = {235, 200, 30};  // yellow tape
inline constexpr Rgb8 kSkinColor = {226, 176, 144};

// The static scene in the table frame, one mesh per object: "floor", "table" (top and legs),
// "play_area_tape", "like_box_tape", "backdrop" (if enabled), "castle" (if chosen). The slider
// block and the hand move and are not included. Validates the options (prefix "scene").
std::vector<NamedMesh> BuildTableScene(const TableSceneOptions& options);

// The names BuildTableScene and the moving objects use; scene.objects may not take them.
inline constexpr const char* kReservedObjectNames[] = {
    "floor",  "table", "play_area_tape", "like_box_tape", "backdrop",
    "castle", "proxy", "hand",           "slider"};

// The slider block: a green 2x2 Duplo brick, model frame as BuildDuploMesh (footprint centred, z =
// 0 at its bottom), 31.8 mm square.
TriangleMesh BuildSliderBlock();
inline constexpr double kSliderBlockSize = TableSetup{}.slider_block_size;  // [m]

// table_T_block for slider value `value` in [-5, 5]: the block stands on the table, centred across
// the Like box, axis-aligned, its centre at TableSetup::SliderCenterX(value). A value outside
// [-5, 5] or NaN is an InputError.
Rigid3 LikeBoxSliderPose(const TableSceneOptions& options, double value);

// The inverse (TableSetup::SliderValue): the slider value of a block whose centre is at
// table_p_block (only x counts). Not clamped: a block pushed beyond the box's ends reads beyond
// +-5; clamp for an annotation.
double SliderValueFromPosition(const TableSceneOptions& options,
                               const Eigen::Vector3d& table_p_block);

// The animator's right hand and forearm, pinching the proxy from above and behind.
//
// Grip frame: the origin is the grasp point, the middle of the top of the part the hand holds (for
// a Duplo figure, the centre of its top face without the studs); place it with proxy_T_grip. With
// the grip frame aligned with the table frame (x right as the camera sees it, y away from the
// camera, z up): the palm is above and behind the origin, facing down, pitched forward by
// hand_pitch; the index to little fingers arch over the top toward the camera (-y) and come down on
// the proxy's front face, the middle fingertip's pad touching the plane y = -grip_width / 2 10 mm
// below the origin; the thumb (on +x, the animator's left, as for a right hand reaching forward)
// comes down behind and touches the back face y = +grip_width / 2 at the same height; the wrist is
// behind the palm and the forearm rises from it away from the camera (+y) and up (+z). So, from the
// camera, the hand hides the proxy's top and part of its back and the fingertips cover the top of
// its front, as a real hand would, and the proxy's volume below the origin between the two faces is
// free of the hand.
struct HandOptions {
  // Uniform size factor about the grasp point (the grip width and forearm length stay as given);
  // 1 = an adult hand (19 cm from wrist to middle fingertip, palm 8 cm wide).
  double scale = 1.0;
  // Distance between the finger pads and the thumb pad [m]: the proxy's depth (y) at the grasp
  // point. Default: a Duplo figure two studs deep (31.8 mm).
  double grip_width = 0.0318;
  // Forward pitch of the palm below horizontal [rad] (0: palm flat, facing straight down).
  double hand_pitch = 0.35;
  // Flexion of the middle finger's joints [rad]: the knuckle joint 0.6 of it, the middle joint 1,
  // the last joint 0.8 (cumulative, so its last phalanx points down at 0.35 + 2.4 * 0.54 = 1.65 rad
  // below horizontal, never less than straight down). With the pinch this sets where the palm is:
  // more curl, a lower palm closer to the grasp point. The other fingers reach the same front plane
  // by inverse kinematics (the little finger 6 mm higher). The pinch holds for grips up to about
  // 5 cm at scale 1.
  double finger_curl = 0.54;
  // Forearm [m]: length from the wrist and elevation of its axis above horizontal [rad], rising
  // away from the camera.
  double forearm_length = 0.25;
  double forearm_elevation = 0.75;
  // Polygon sides of the fingers' cross-sections (twice as many for the wrist and forearm).
  int segments = 8;

  template <class V>
  void VisitFields(V& v) {
    v("scale", scale);
    v("grip_width", grip_width);
    v("hand_pitch", hand_pitch);
    v("finger_curl", finger_curl);
    v("forearm_length", forearm_length);
    v("forearm_elevation", forearm_elevation);
    v("segments", segments);
  }
  // Ranges: scale [0.5, 2], grip_width [0.01, 0.08] m, hand_pitch [-0.5, 1.4] rad, finger_curl
  // [0, 1.2] rad, forearm_length [0.05, 0.5] m, forearm_elevation [0, 1.5] rad, segments [3, 64].
  void Validate(const std::string& prefix) const;
};

// The hand and forearm in the grip frame (skin colour kSkinColor). About 1500 triangles with the
// default 8 segments. Validates the options (prefix "hand").
TriangleMesh BuildHandAndForearm(const HandOptions& options);

}  // namespace mmh::sim
