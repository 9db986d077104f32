#include "sim/props.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.h"
#include "sim/duplo.h"
#include "sim/primitives.h"

namespace mmh::sim {
namespace {

constexpr std::pair<TableProps, const char*> kPropsNames[] = {
    {TableProps::kNone, "none"},
    {TableProps::kCastle, "castle"},
};

// Castle layout [m] (BuildCastle): footprint and the gap between the play area and its front.
constexpr double kCastleWidth = 0.30;
constexpr double kCastleDepth = 0.16;
constexpr double kCastleGap = 0.04;

constexpr Rgb8 kFloorColor = {118, 108, 96};
constexpr Rgb8 kWallColor = {212, 206, 194};
constexpr Rgb8 kCastleStoneColor = {160, 165, 169};  // Duplo light bluish grey
constexpr Rgb8 kCastleDoorColor = {88, 42, 18};      // reddish brown
constexpr Rgb8 kFlagColor = {201, 26, 9};            // red

void CheckSize(const std::string& key, double value, double max) {
  if (!std::isfinite(value) || value <= 0 || value > max) {
    ThrowBadValue(key, FormatNumber(value), "a size in (0, " + FormatNumber(max) + "] m");
  }
}

void AppendBox(const Eigen::Vector3d& min, const Eigen::Vector3d& max, const Rgb8& color,
               TriangleMesh* mesh) {
  AppendMesh(MakeBoxBetween(min, max, color), Rigid3::Identity(), mesh);
}

// Tape of `width` laid outside the rectangle [x0, x1] x [y0, y1] on the table top: four boxes that
// touch but do not overlap.
TriangleMesh BuildTapeOutline(double x0, double x1, double y0, double y1, double width,
                              double thickness, const Rgb8& color) {
  TriangleMesh mesh;
  AppendBox({x0 - width, y0 - width, 0}, {x1 + width, y0, thickness}, color, &mesh);  // front
  AppendBox({x0 - width, y1, 0}, {x1 + width, y1 + width, thickness}, color, &mesh);  // back
  AppendBox({x0 - width, y0, 0}, {x0, y1, thickness}, color, &mesh);                  // left
  AppendBox({x1, y0, 0}, {x1 + width, y1, thickness}, color, &mesh);                  // right
  return mesh;
}

// Merlons (the raised blocks of crenellations) of `size` [m] along x from x0 to x1 at y in
// [y0, y1], standing on z = top: as many as fit with gaps equal to their width, centred.
void AppendMerlonsAlongX(double x0, double x1, double y0, double y1, double top, double size,
                         TriangleMesh* mesh) {
  const int count = static_cast<int>(std::floor((x1 - x0 + size) / (2 * size)));
  const double start = 0.5 * (x0 + x1) - 0.5 * (2 * count - 1) * size;
  for (int i = 0; i < count; ++i) {
    const double x = start + 2 * i * size;
    AppendBox({x, y0, top}, {x + size, y1, top + size}, kCastleStoneColor, mesh);
  }
}
void AppendMerlonsAlongY(double x0, double x1, double y0, double y1, double top, double size,
                         TriangleMesh* mesh) {
  const int count = static_cast<int>(std::floor((y1 - y0 + size) / (2 * size)));
  const double start = 0.5 * (y0 + y1) - 0.5 * (2 * count - 1) * size;
  for (int i = 0; i < count; ++i) {
    const double y = start + 2 * i * size;
    AppendBox({x0, y, top}, {x1, y + size, top + size}, kCastleStoneColor, mesh);
  }
}

// A Duplo-style castle centred on x = 0 with its front face at y = front, standing on z = 0:
// walls 2 cm thick and 14 cm tall around a courtyard, four 5 cm square towers 20 cm tall at the
// corners, 2 cm merlons on walls and towers, a 6 x 9 cm gate in the front wall with a door
// recessed 8 mm, a red flag on the back-left tower. About 540 triangles.
TriangleMesh BuildCastle(double front) {
  constexpr double kWall = 0.02;  // wall thickness
  constexpr double kWallHeight = 0.14;
  constexpr double kTower = 0.05;  // tower side
  constexpr double kTowerHeight = 0.20;
  constexpr double kMerlon = 0.02;
  constexpr double kGateWidth = 0.06;
  constexpr double kGateHeight = 0.09;
  constexpr double kDoorRecess = 0.008;
  const double x0 = -0.5 * kCastleWidth;
  const double x1 = 0.5 * kCastleWidth;
  const double y0 = front;
  const double y1 = front + kCastleDepth;
  TriangleMesh mesh;

  // Towers with a merlon on each corner of their tops.
  for (const double tx : {x0, x1 - kTower}) {
    for (const double ty : {y0, y1 - kTower}) {
      AppendBox({tx, ty, 0}, {tx + kTower, ty + kTower, kTowerHeight}, kCastleStoneColor, &mesh);
      for (const double mx : {tx, tx + kTower - kMerlon}) {
        for (const double my : {ty, ty + kTower - kMerlon}) {
          AppendBox({mx, my, kTowerHeight}, {mx + kMerlon, my + kMerlon, kTowerHeight + kMerlon},
                    kCastleStoneColor, &mesh);
        }
      }
    }
  }
  // Front wall with the gate, and the door set back in it.
  const double wx0 = x0 + kTower;
  const double wx1 = x1 - kTower;
  const double gx0 = -0.5 * kGateWidth;
  const double gx1 = 0.5 * kGateWidth;
  AppendBox({wx0, y0, 0}, {gx0, y0 + kWall, kWallHeight}, kCastleStoneColor, &mesh);
  AppendBox({gx1, y0, 0}, {wx1, y0 + kWall, kWallHeight}, kCastleStoneColor, &mesh);
  AppendBox({gx0, y0, kGateHeight}, {gx1, y0 + kWall, kWallHeight}, kCastleStoneColor, &mesh);
  AppendBox({gx0, y0 + kDoorRecess, 0}, {gx1, y0 + kWall, kGateHeight}, kCastleDoorColor, &mesh);
  // Back and side walls.
  AppendBox({wx0, y1 - kWall, 0}, {wx1, y1, kWallHeight}, kCastleStoneColor, &mesh);
  const double wy0 = y0 + kTower;
  const double wy1 = y1 - kTower;
  AppendBox({x0, wy0, 0}, {x0 + kWall, wy1, kWallHeight}, kCastleStoneColor, &mesh);
  AppendBox({x1 - kWall, wy0, 0}, {x1, wy1, kWallHeight}, kCastleStoneColor, &mesh);
  // Crenellations on the walls.
  AppendMerlonsAlongX(wx0, wx1, y0, y0 + kWall, kWallHeight, kMerlon, &mesh);
  AppendMerlonsAlongX(wx0, wx1, y1 - kWall, y1, kWallHeight, kMerlon, &mesh);
  AppendMerlonsAlongY(x0, x0 + kWall, wy0, wy1, kWallHeight, kMerlon, &mesh);
  AppendMerlonsAlongY(x1 - kWall, x1, wy0, wy1, kWallHeight, kMerlon, &mesh);
  // Flag pole and flag on the back-left tower.
  const double px = x0 + 0.5 * kTower;
  const double py = y1 - 0.5 * kTower;
  constexpr double kPole = 0.004;
  constexpr double kPoleHeight = 0.06;
  AppendBox({px - 0.5 * kPole, py - 0.5 * kPole, kTowerHeight},
            {px + 0.5 * kPole, py + 0.5 * kPole, kTowerHeight + kPoleHeight}, kCastleDoorColor,
            &mesh);
  AppendBox({px + 0.5 * kPole, py - 0.001, kTowerHeight + kPoleHeight - 0.022},
            {px + 0.5 * kPole + 0.035, py + 0.001, kTowerHeight + kPoleHeight}, kFlagColor, &mesh);
  return mesh;
}

// Rotation whose columns are the given orthonormal right-handed axes.
Eigen::Quaterniond FromAxes(const Eigen::Vector3d& x, const Eigen::Vector3d& y,
                            const Eigen::Vector3d& z) {
  Eigen::Matrix3d m;
  m.col(0) = x;
  m.col(1) = y;
  m.col(2) = z;
  return Eigen::Quaterniond(m).normalized();
}

// The middle joint of a two-link chain of lengths l1, l2 from `base` toward `target`, on the side
// of the base-target line that `bulge` points to. A target out of reach (too far or too near)
// leaves the chain straight (or folded) toward it.
Eigen::Vector3d TwoLinkJoint(const Eigen::Vector3d& base, const Eigen::Vector3d& target, double l1,
                             double l2, const Eigen::Vector3d& bulge) {
  const Eigen::Vector3d to_target = target - base;
  const double reach = std::clamp(to_target.norm(), std::abs(l1 - l2) + 1e-9, l1 + l2 - 1e-9);
  const Eigen::Vector3d along = to_target.normalized();
  const Eigen::Vector3d side = (bulge - bulge.dot(along) * along).normalized();
  const double foot = (l1 * l1 - l2 * l2 + reach * reach) / (2 * reach);
  return base + along * foot + side * std::sqrt(std::max(0.0, l1 * l1 - foot * foot));
}

// Scales a mesh's vertices by (sx, sy, sz) about its origin (orientation is kept for positive
// factors).
TriangleMesh Scaled(TriangleMesh mesh, const Eigen::Vector3f& factors) {
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    mesh.vertices.row(i) = mesh.vertices.row(i).cwiseProduct(factors.transpose());
  }
  return mesh;
}

}  // namespace

std::span<const std::pair<TableProps, const char*>> EnumNames(TableProps) { return kPropsNames; }

void TableSceneOptions::Validate(const std::string& prefix) const {
  CheckSize(prefix + ".table_width", table_width, 10.0);
  CheckSize(prefix + ".table_depth", table_depth, 10.0);
  CheckSize(prefix + ".table_thickness", table_thickness, 0.5);
  CheckSize(prefix + ".table_height", table_height, 3.0);
  if (table_height <= table_thickness) {
    ThrowBadValue(prefix + ".table_height", FormatNumber(table_height),
                  "a height above the floor greater than table_thickness (" +
                      FormatNumber(table_thickness) + " m)");
  }
  CheckSize(prefix + ".play_area_width", play_area_width, 10.0);
  CheckSize(prefix + ".play_area_depth", play_area_depth, 10.0);
  CheckSize(prefix + ".like_box_length", like_box_length, 10.0);
  CheckSize(prefix + ".like_box_width", like_box_width, 10.0);
  CheckSize(prefix + ".tape_width", tape_width, 0.1);
  if (tape_thickness != 0) CheckSize(prefix + ".tape_thickness", tape_thickness, 0.01);
  for (const auto& [key, value] :
       {std::pair<const char*, double>{"table_x", table_x}, {"table_y", table_y}}) {
    if (!std::isfinite(value) || std::abs(value) > 10.0) {
      ThrowBadValue(prefix + "." + key, FormatNumber(value), "a position in [-10, 10] m");
    }
  }
  if (!std::isfinite(table_yaw_deg) || std::abs(table_yaw_deg) > 180.0) {
    ThrowBadValue(prefix + ".table_yaw_deg", FormatNumber(table_yaw_deg),
                  "a turn about z in [-180, 180] degrees");
  }
  materials.Validate(prefix + ".materials");
  for (size_t i = 0; i < objects.size(); ++i) {
    const std::string key = prefix + ".objects[" + std::to_string(i) + "]";
    objects[i].Validate(key);
    for (size_t j = 0; j < i; ++j) {
      if (objects[j].name == objects[i].name) {
        ThrowBadValue(key + ".name", "\"" + objects[i].name + "\"",
                      "a name no other object has (objects[" + std::to_string(j) + "] has it)");
      }
    }
  }
  if (!std::isfinite(like_box_center_x)) {
    ThrowBadValue(prefix + ".like_box_center_x", FormatNumber(like_box_center_x), "a finite x [m]");
  }
  if (!std::isfinite(like_box_center_y)) {
    ThrowBadValue(prefix + ".like_box_center_y", FormatNumber(like_box_center_y), "a finite y [m]");
  }
  if (like_box_length <= slider_block_size) {
    ThrowBadValue(prefix + ".like_box_length", FormatNumber(like_box_length),
                  "a length greater than the slider block (" + FormatNumber(slider_block_size) +
                      " m) so that the block can slide");
  }
  if (like_box_width < slider_block_size) {
    ThrowBadValue(
        prefix + ".like_box_width", FormatNumber(like_box_width),
        "a width of at least the slider block (" + FormatNumber(slider_block_size) + " m)");
  }
  const double half_w = 0.5 * table_width;
  const double half_d = 0.5 * table_depth;
  // Where a rectangle of the table frame leaves the table top: 1 if a corner lies beyond the top's
  // width, 2 beyond its depth (in the top's own frame, TableTTop), 0 if it lies on it.
  const Rigid3 table_T_top = TableTTop();
  const Rigid3 top_T_table = table_T_top.Inverse();
  auto off_table = [&](double x0, double x1, double y0, double y1) {
    for (const double x : {x0, x1}) {
      for (const double y : {y0, y1}) {
        const Eigen::Vector3d p = top_T_table * Eigen::Vector3d(x, y, 0.0);
        if (std::abs(p.x()) > half_w) return 1;
        if (std::abs(p.y()) > half_d) return 2;
      }
    }
    return 0;
  };
  const bool moved = table_x != 0 || table_y != 0 || table_yaw_deg != 0;
  const std::string where = moved ? " (centred at " + FormatNumber(table_x) + ", " +
                                        FormatNumber(table_y) + " m, turned " +
                                        FormatNumber(table_yaw_deg) + " deg)"
                                  : "";
  const double area_x = 0.5 * play_area_width + tape_width;
  const double area_y = 0.5 * play_area_depth + tape_width;
  switch (off_table(-area_x, area_x, -area_y, area_y)) {
    case 1:
      ThrowBadValue(prefix + ".play_area_width", FormatNumber(play_area_width),
                    "a play area that, with its tape, fits on the " + FormatNumber(table_width) +
                        " m wide table" + where);
    case 2:
      ThrowBadValue(prefix + ".play_area_depth", FormatNumber(play_area_depth),
                    "a play area that, with its tape, fits on the " + FormatNumber(table_depth) +
                        " m deep table" + where);
  }
  const double box_x0 = like_box_center_x - 0.5 * like_box_length - tape_width;
  const double box_x1 = like_box_center_x + 0.5 * like_box_length + tape_width;
  const double box_y0 = like_box_center_y - 0.5 * like_box_width - tape_width;
  const double box_y1 = like_box_center_y + 0.5 * like_box_width + tape_width;
  switch (off_table(box_x0, box_x1, box_y0, box_y1)) {
    case 1:
      ThrowBadValue(prefix + ".like_box_center_x", FormatNumber(like_box_center_x),
                    "a Like box that, with its tape, lies on the table (x in [" +
                        FormatNumber(-half_w) + ", " + FormatNumber(half_w) + "] m" +
                        (moved ? " of the table's centre" + where : std::string()) + ")");
    case 2:
      ThrowBadValue(prefix + ".like_box_center_y", FormatNumber(like_box_center_y),
                    "a Like box that, with its tape, lies on the table (y in [" +
                        FormatNumber(-half_d) + ", " + FormatNumber(half_d) + "] m" +
                        (moved ? " of the table's centre" + where : std::string()) + ")");
  }
  if (box_x0 < area_x && box_x1 > -area_x && box_y0 < area_y && box_y1 > -area_y) {
    ThrowBadValue(prefix + ".like_box_center_x",
                  FormatNumber(like_box_center_x) + " (with like_box_center_y " +
                      FormatNumber(like_box_center_y) + ")",
                  "a Like box (with its tape) clear of the play area (with its tape)");
  }
  // The table top's farthest corner from the camera side (half_d for the default table).
  double far_edge = -10.0;
  for (const double x : {-half_w, half_w}) {
    for (const double y : {-half_d, half_d}) {
      far_edge = std::max(far_edge, (table_T_top * Eigen::Vector3d(x, y, 0.0)).y());
    }
  }
  if (backdrop && (!std::isfinite(backdrop_y) || backdrop_y < far_edge || backdrop_y > 10.0)) {
    ThrowBadValue(prefix + ".backdrop_y", FormatNumber(backdrop_y),
                  std::string("a wall behind the table: y in [") +
                      (moved ? "the table's far corner" : "table_depth / 2") + " = " +
                      FormatNumber(far_edge) + ", 10] m");
  }
  const double castle_y0 = 0.5 * play_area_depth + kCastleGap;
  if (props == TableProps::kCastle && off_table(-0.5 * kCastleWidth, 0.5 * kCastleWidth, castle_y0,
                                                castle_y0 + kCastleDepth) != 0) {
    ThrowBadValue(prefix + ".props", "\"castle\"",
                  "a table deep enough for the castle behind the play area (table_depth >= " +
                      FormatNumber(play_area_depth + 2 * (kCastleGap + kCastleDepth)) + " m)");
  }
}

void SceneObject::Validate(const std::string& prefix) const {
  if (name.empty()) ThrowBadValue(prefix + ".name", "\"\"", "a name for the object");
  for (const char* reserved : kReservedObjectNames) {
    if (name == reserved) {
      ThrowBadValue(prefix + ".name", "\"" + name + "\"",
                    "a name other than the scene's own objects' (floor, table, play_area_tape, "
                    "like_box_tape, backdrop, castle, proxy, hand, slider)");
    }
  }
  if (mesh.empty()) ThrowBadValue(prefix + ".mesh", "\"\"", "an OBJ, PLY or Duplo .json file");
  if (!(scale > 0) || !std::isfinite(scale)) {
    ThrowBadValue(prefix + ".scale", FormatNumber(scale), "a positive finite factor");
  }
  for (const auto& [key, value] : {std::pair{"x", x}, {"y", y}, {"z", z}}) {
    if (!(std::abs(value) <= 100.0)) {
      ThrowBadValue(prefix + "." + key, FormatNumber(value), "a finite position within 100 m");
    }
  }
  const double norm = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
  if (!(std::abs(norm - 1.0) <= 1e-3)) {
    ThrowBadValue(prefix + ".qx, qy, qz, qw",
                  FormatNumber(qx) + ", " + FormatNumber(qy) + ", " + FormatNumber(qz) + ", " +
                      FormatNumber(qw) + " (norm " + FormatNumber(norm) + ")",
                  "a unit quaternion (norm within 1e-3 of 1)");
  }
  material.Validate(prefix + ".material");
}

Rigid3 SceneObject::TableTObject() const {
  return Rigid3(Eigen::Quaterniond(qw, qx, qy, qz).normalized(), Eigen::Vector3d(x, y, z));
}

Rigid3 TableSceneOptions::TableTTop() const {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(table_yaw_deg * std::numbers::pi / 180.0,
                                                     Eigen::Vector3d::UnitZ())),
                Eigen::Vector3d(table_x, table_y, 0.0));
}

std::vector<NamedMesh> BuildTableScene(const TableSceneOptions& options) {
  options.Validate("scene");
  const double half_w = 0.5 * options.table_width;
  const double half_d = 0.5 * options.table_depth;
  const double floor_z = -options.table_height;
  std::vector<NamedMesh> scene;

  const double far_y = options.backdrop ? options.backdrop_y : 4.0;
  scene.push_back(
      {"floor", MakeBoxBetween({-2.0, -2.5, floor_z - 0.02}, {2.0, far_y, floor_z}, kFloorColor)});

  TriangleMesh table = MakeBoxBetween({-half_w, -half_d, -options.table_thickness},
                                      {half_w, half_d, 0.0}, kTableColor);
  constexpr double kLeg = 0.05;
  constexpr double kLegInset = 0.05;
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) {
      const double cx = sx * (half_w - kLegInset - 0.5 * kLeg);
      const double cy = sy * (half_d - kLegInset - 0.5 * kLeg);
      AppendBox({cx - 0.5 * kLeg, cy - 0.5 * kLeg, floor_z},
                {cx + 0.5 * kLeg, cy + 0.5 * kLeg, -options.table_thickness}, kTableColor, &table);
    }
  }
  if (options.table_x != 0 || options.table_y != 0 || options.table_yaw_deg != 0) {
    TriangleMesh moved;
    AppendMesh(table, options.TableTTop(), &moved);
    table = std::move(moved);
  }
  scene.push_back({"table", std::move(table)});

  if (options.tape_thickness > 0) {
    scene.push_back(
        {"play_area_tape",
         BuildTapeOutline(-0.5 * options.play_area_width, 0.5 * options.play_area_width,
                          -0.5 * options.play_area_depth, 0.5 * options.play_area_depth,
                          options.tape_width, options.tape_thickness, kPlayAreaTapeColor)});
    scene.push_back(
        {"like_box_tape",
         BuildTapeOutline(options.like_box_center_x - 0.5 * options.like_box_length,
                          options.like_box_center_x + 0.5 * options.like_box_length,
                          options.like_box_center_y - 0.5 * options.like_box_width,
                          options.like_box_center_y + 0.5 * options.like_box_width,
                          options.tape_width, options.tape_thickness, kLikeBoxTapeColor)});
  }
  if (options.backdrop) {
    scene.push_back(
        {"backdrop", MakeBoxBetween({-1.5, options.backdrop_y, floor_z},
                                    {1.5, options.backdrop_y + 0.05, 1.25}, kWallColor)});
  }
  if (options.props == TableProps::kCastle) {
    scene.push_back({"castle", BuildCastle(0.5 * options.play_area_depth + kCastleGap)});
  }
  return scene;
}

TriangleMesh BuildSliderBlock() { return MakeDuploBrick("2x2", kDuploGreen); }

Rigid3 LikeBoxSliderPose(const TableSceneOptions& options, double value) {
  if (!(value >= -5.0 && value <= 5.0)) {
    ThrowBadValue("slider value", FormatNumber(value), "a value in [-5, 5]");
  }
  options.Validate("scene");
  return Rigid3(Eigen::Quaterniond::Identity(),
                {options.SliderCenterX(value), options.like_box_center_y, 0.0});
}

double SliderValueFromPosition(const TableSceneOptions& options,
                               const Eigen::Vector3d& table_p_block) {
  return options.SliderValue(table_p_block.x());
}

void HandOptions::Validate(const std::string& prefix) const {
  auto check = [&](const char* key, double value, double lo, double hi, const char* what) {
    if (!std::isfinite(value) || value < lo || value > hi) {
      ThrowBadValue(prefix + "." + key, FormatNumber(value),
                    std::string(what) + " in [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]");
    }
  };
  check("scale", scale, 0.5, 2.0, "a size factor");
  check("hand_pitch", hand_pitch, -0.5, 1.4, "a pitch below horizontal [rad]");
  check("finger_curl", finger_curl, 0.0, 1.2, "a flexion per joint [rad]");
  check("forearm_length", forearm_length, 0.05, 0.5, "a length [m]");
  check("forearm_elevation", forearm_elevation, 0.0, 1.5, "an elevation above horizontal [rad]");
  check("grip_width", grip_width, 0.01, 0.08, "a width [m]");
  if (segments < 3 || segments > 64) {
    ThrowBadValue(prefix + ".segments", std::to_string(segments), "an integer in [3, 64]");
  }
}

namespace {

// The hand's geometry, built at adult size (scaled at the end, so the grip is built for
// grip_width / scale). The palm frame: u across the palm toward the thumb, a from the wrist to the
// knuckles, n out of the palm's inner face (u x a = n, right-handed).
struct HandFrame {
  int segments = 16;
  double half_grip = 0.0;
  double pitch = 0.0;
  Eigen::Vector3d u, a, n;
  Eigen::Vector3d palm;  // the palm's centre
};

// Palm [m]: width along u, length along a, thickness along n: a slab with rounded edges.
constexpr double kPalmWidth = 0.080;
constexpr double kPalmLength = 0.090;
constexpr double kPalmThickness = 0.026;
constexpr double kPalmEdgeA = 0.5 * (kPalmLength - kPalmThickness);
constexpr double kPalmEdgeU = 0.5 * (kPalmWidth - kPalmThickness);
constexpr double kPalmEdgeRadius = 0.5 * kPalmThickness;
// The fingertips' and the thumb's pads are this far below the grasp point.
constexpr double kPinchDepth = 0.010;

// Fingers: offset along u, set-back of the knuckle along -a, radius, phalanx lengths [m]. The
// joints flex by 0.6, 1 and 0.8 times finger_curl, cumulatively, toward the palm side.
struct Finger {
  double offset, setback, radius;
  double lengths[3];
};
constexpr Finger kFingers[] = {
    {0.029, 0.004, 0.0090, {0.044, 0.026, 0.020}},   // index
    {0.010, 0.000, 0.0092, {0.048, 0.030, 0.021}},   // middle
    {-0.009, 0.004, 0.0088, {0.045, 0.028, 0.020}},  // ring
    {-0.027, 0.014, 0.0078, {0.036, 0.021, 0.018}},  // little
};

double PhalanxRadius(const Finger& finger, int j) { return finger.radius * (1.0 - 0.07 * j); }

// The last phalanx's length includes its rounded tip.
double PhalanxLength(const Finger& finger, int j) {
  return finger.lengths[j] - (j == 2 ? PhalanxRadius(finger, j) : 0.0);
}

// The direction of each phalanx of a curled finger.
struct FingerCurl {
  double joint_angles[3];
  Eigen::Vector3d Direction(const HandFrame& h, int j) const {
    return Eigen::Vector3d(h.a * std::cos(joint_angles[j]) + h.n * std::sin(joint_angles[j]));
  }
};

// The last phalanx at least straight down (angle pi/2 below horizontal) so it never leans into the
// proxy.
FingerCurl Curl(const HandOptions& options) {
  const double k = options.finger_curl;
  return {{0.6 * k, 1.6 * k, std::max(2.4 * k, 0.5 * std::numbers::pi - options.hand_pitch)}};
}

// The palm placed so that the middle fingertip's pad touches the proxy's front: its tip centre at
// y = -(half_grip + radius), kPinchDepth below the grasp point (in the grip frame's y-z plane).
HandFrame PlaceHand(const HandOptions& options, const FingerCurl& curl) {
  HandFrame h;
  h.segments = options.segments;
  h.half_grip = 0.5 * options.grip_width / options.scale;
  h.pitch = options.hand_pitch;
  h.u = Eigen::Vector3d::UnitX();
  h.a = Eigen::Vector3d(0.0, -std::cos(h.pitch), -std::sin(h.pitch));
  h.n = h.u.cross(h.a);
  const Finger& middle = kFingers[1];
  Eigen::Vector3d knuckle_to_tip = Eigen::Vector3d::Zero();
  for (int j = 0; j < 3; ++j) knuckle_to_tip += curl.Direction(h, j) * PhalanxLength(middle, j);
  const Eigen::Vector3d middle_tip(middle.offset, -(h.half_grip + PhalanxRadius(middle, 2)),
                                   -kPinchDepth);
  h.palm = middle_tip - knuckle_to_tip - h.a * (kPalmEdgeA - middle.setback) - h.u * middle.offset;
  return h;
}

void AppendPalm(const HandFrame& h, TriangleMesh* mesh) {
  const Rgb8 skin = kSkinColor;
  AppendMesh(
      MakeBox({kPalmWidth - kPalmThickness, kPalmLength - kPalmThickness, kPalmThickness}, skin),
      Rigid3(FromAxes(h.u, h.a, h.n), h.palm), mesh);
  for (const double s : {-1.0, 1.0}) {
    AppendMesh(MakeCapsuleBetween(h.palm + s * h.a * kPalmEdgeA - h.u * kPalmEdgeU,
                                  h.palm + s * h.a * kPalmEdgeA + h.u * kPalmEdgeU, kPalmEdgeRadius,
                                  h.segments, skin),
               Rigid3::Identity(), mesh);
    AppendMesh(MakeCapsuleBetween(h.palm + s * h.u * kPalmEdgeU - h.a * kPalmEdgeA,
                                  h.palm + s * h.u * kPalmEdgeU + h.a * kPalmEdgeA, kPalmEdgeRadius,
                                  h.segments, skin),
               Rigid3::Identity(), mesh);
  }
}

// Each finger's last phalanx points down at the nominal angle with its tip's pad on the front
// plane (the little finger, the shortest, a little higher); the proximal and middle phalanges
// reach its last joint by two-link inverse kinematics, the middle joint bulging to the back of the
// hand. For the middle finger this is the nominal pose the palm was placed by.
void AppendFingers(const HandFrame& h, const FingerCurl& curl, TriangleMesh* mesh) {
  const Rgb8 skin = kSkinColor;
  const Eigen::Vector3d last_direction = curl.Direction(h, 2);
  for (const Finger& finger : kFingers) {
    const Eigen::Vector3d knuckle =
        h.palm + h.a * (kPalmEdgeA - finger.setback) + h.u * finger.offset;
    const double tip_radius = PhalanxRadius(finger, 2);
    const double lift = &finger == &kFingers[3] ? 0.006 : 0.0;
    const Eigen::Vector3d tip(finger.offset, -(h.half_grip + tip_radius), -kPinchDepth + lift);
    const Eigen::Vector3d last_joint = tip - last_direction * PhalanxLength(finger, 2);
    const Eigen::Vector3d middle_joint =
        TwoLinkJoint(knuckle, last_joint, PhalanxLength(finger, 0), PhalanxLength(finger, 1), -h.n);
    AppendMesh(
        MakeCapsuleBetween(knuckle, middle_joint, PhalanxRadius(finger, 0), h.segments, skin),
        Rigid3::Identity(), mesh);
    AppendMesh(
        MakeCapsuleBetween(middle_joint, last_joint, PhalanxRadius(finger, 1), h.segments, skin),
        Rigid3::Identity(), mesh);
    AppendMesh(MakeCapsuleBetween(last_joint, tip, tip_radius, h.segments, skin),
               Rigid3::Identity(), mesh);
  }
}

// Thumb: the metacarpal (the thenar eminence) from the middle of the palm's +u side, then the two
// phalanges, reaching the proxy's back face (pad at y = +half_grip, kPinchDepth below the grasp
// point, a little toward +x). Two-link inverse kinematics, the knuckle bulging outward (+x) and
// up; a target out of reach leaves the thumb stretched toward it.
void AppendThumb(const HandFrame& h, TriangleMesh* mesh) {
  const Rgb8 skin = kSkinColor;
  constexpr double kMetacarpal = 0.046;
  constexpr double kThumbTip = 0.052;  // both phalanges, straight, to the tip's centre
  constexpr double kThumbRadius = 0.0105;
  const Eigen::Vector3d thumb_base =
      h.palm + h.u * kPalmEdgeU + h.n * (0.5 * kPalmThickness - 0.008);
  const Eigen::Vector3d thumb_tip(0.006, h.half_grip + kThumbRadius, -kPinchDepth);
  const Eigen::Vector3d thumb_knuckle =
      TwoLinkJoint(thumb_base, thumb_tip, kMetacarpal, kThumbTip, h.u + Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d thumb_end =
      thumb_knuckle + (thumb_tip - thumb_knuckle).normalized() * kThumbTip;
  AppendMesh(MakeCapsuleBetween(thumb_base, thumb_knuckle, 0.014, h.segments, skin),
             Rigid3::Identity(), mesh);
  AppendMesh(MakeCapsuleBetween(thumb_knuckle, thumb_end, kThumbRadius, h.segments, skin),
             Rigid3::Identity(), mesh);
}

// Wrist and forearm: an oval cross-section (1.3 times wider across u than deep), 48 mm deep at the
// wrist and 72 mm at the far end, rising from the heel of the palm at forearm_elevation.
void AppendForearm(const HandFrame& h, const HandOptions& options, TriangleMesh* mesh) {
  const Rgb8 skin = kSkinColor;
  const Eigen::Vector3d wrist = h.palm - h.a * (0.5 * kPalmLength - 0.006);
  const Eigen::Vector3d f(0.0, std::cos(options.forearm_elevation),
                          std::sin(options.forearm_elevation));
  const Eigen::Quaterniond forearm_rotation = FromAxes(h.u, f.cross(h.u), f);
  const Eigen::Vector3f oval(1.3f, 1.0f, 1.0f);
  constexpr double kWristRadius = 0.024;
  constexpr double kElbowRadius = 0.036;
  AppendMesh(Scaled(MakeSphere(kWristRadius, 2 * h.segments, skin), oval),
             Rigid3(forearm_rotation, wrist), mesh);
  AppendMesh(Scaled(MakeFrustum(kWristRadius, kElbowRadius, options.forearm_length / options.scale,
                                2 * h.segments, skin),
                    oval),
             Rigid3(forearm_rotation, wrist), mesh);
}

}  // namespace

TriangleMesh BuildHandAndForearm(const HandOptions& options) {
  options.Validate("hand");
  const FingerCurl curl = Curl(options);
  const HandFrame hand = PlaceHand(options, curl);
  TriangleMesh mesh;
  AppendPalm(hand, &mesh);
  AppendFingers(hand, curl, &mesh);
  AppendThumb(hand, &mesh);
  AppendForearm(hand, options, &mesh);
  if (options.scale != 1.0) mesh.vertices *= static_cast<float>(options.scale);
  return mesh;
}

}  // namespace mmh::sim
