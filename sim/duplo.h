// Duplo proxies: assemblies of Duplo bricks on a stud grid, read from JSON and built into meshes
// with the real bricks' dimensions, so that an assembly looks to a depth camera like the real toy
// the paper's animators held.
//
// JSON form (configs/proxies/*.json):
//
//   {"name": "soldier", "description": "...",
//    "bricks": [{"type": "2x4", "at": [0, 0, 0], "rotated": true, "color": "black"},
//               {"type": "2x2", "at": [1, 0, 1], "color": [242, 205, 55]}, ...]}
//
// "type" is a catalogue name (DuploBrickTypes), "at" the stud-grid cell [x, y] of the brick's
// corner stud (its smallest x and y) and its layer (0 = on the table), "rotated" (optional, default
// false) swaps the footprint's x and y extents, "color" a named colour (DuploColors) or 8-bit sRGB
// [r, g, b]. "name" and "description" are optional.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/triangle_mesh.h"

namespace mmh::sim {

// Duplo dimensions [m] (LEGO Duplo: twice the LEGO System module). A brick of n x m studs
// measures n * pitch - clearance by m * pitch - clearance, so neighbouring bricks leave a 0.2 mm
// gap.
inline constexpr double kDuploPitch = 0.016;          // stud spacing
inline constexpr double kDuploClearance = 0.0002;     // footprint shortfall per brick
inline constexpr double kDuploBrickHeight = 0.0192;   // body height without studs
inline constexpr double kDuploStudDiameter = 0.0096;  // stud cylinder
inline constexpr double kDuploStudHeight = 0.0045;    // stud above the brick's top
inline constexpr int kDuploDefaultStudSegments = 16;  // polygon sides of a stud

// A catalogue brick type: "NxM" covers N studs along x and M along y when not rotated.
struct DuploBrickType {
  const char* name;
  int studs_x;
  int studs_y;
};
// The catalogue, full-height bricks only (layers stay on one integer grid): 1x1, 1x2, 1x3, 1x4,
// 2x2, 2x3, 2x4, 2x6, 2x8, 4x4. Rotate a brick to lay it the other way ("4x2" is "2x4" rotated).
std::span<const DuploBrickType> DuploBrickTypes();
// The type with this name, or nullopt.
std::optional<DuploBrickType> FindDuploBrickType(const std::string& name);

// Named colours: approximately LEGO's own sRGB values (Rebrickable's colour table), e.g. red
// (201, 26, 9), blue (0, 85, 191), yellow (242, 205, 55), green (35, 120, 65), white, black,
// orange, lime, bright_green, dark_blue, medium_blue, light_gray, dark_gray, tan, reddish_brown,
// light_nougat (the skin of Duplo figures), nougat, dark_red, pink, purple, azure.
struct DuploColor {
  const char* name;
  Rgb8 rgb;
};
std::span<const DuploColor> DuploColors();
// The colour with this name, or nullopt.
std::optional<Rgb8> FindDuploColor(const std::string& name);
// The colour of the slider block (a green 2x2 brick) and of the LEGO green it is made of.
inline constexpr Rgb8 kDuploGreen = {35, 120, 65};

struct DuploBrick {
  std::string type = "2x2";  // catalogue name
  int x = 0;                 // stud-grid cell of the corner stud with the smallest x and y
  int y = 0;
  int level = 0;         // layer, 0 = bottom; layer L spans z in [L, L + 1] * kDuploBrickHeight
  bool rotated = false;  // footprint studs_y along x and studs_x along y
  Rgb8 color = {201, 26, 9};
};

struct DuploAssembly {
  std::string name;         // optional, for messages and file names
  std::string description;  // optional
  std::vector<DuploBrick> bricks;
};

// Reads the JSON form above. Unknown keys (with a did-you-mean), unknown brick types and colours,
// values of the wrong type or range, an empty brick list, bricks sharing a cell and bricks with
// nothing beneath them are InputErrors naming `where` (a file name or key path) and the brick, e.g.
// "proxy.bricks[3].type: got \"2x5\", expected ...".
DuploAssembly ParseDuploAssembly(const nlohmann::json& json, const std::string& where);

// Reads a JSON file of the form above (errors name the file).
DuploAssembly LoadDuploAssembly(const std::filesystem::path& path);

// The JSON form; a colour that has a name is written by its name. ParseDuploAssembly of the result
// gives back the assembly.
nlohmann::json DuploAssemblyToJson(const DuploAssembly& assembly);

// The checks of ParseDuploAssembly on an assembly built in code: known types, at least one brick,
// no shared cells, every brick above layer 0 resting on at least one brick of the layer below, grid
// positions within +-1000 studs and layers in [0, 100].
void ValidateDuploAssembly(const DuploAssembly& assembly, const std::string& where);

// Footprint of a brick in studs along x and y, after rotation (the type must be known).
Eigen::Vector2i DuploFootprint(const DuploBrick& brick);

// The assembly's mesh in its model frame: x and y centred on the bounding box of the bricks'
// footprints, z = 0 at the bottom of layer 0, z up. Each brick is a solid box (real bricks are
// hollow underneath; a camera above a table does not see that) with a solid cylindrical stud on
// every cell not covered by a brick of the layer above. Every brick body and stud is a closed part,
// so the mesh is closed and its volume is the sum of theirs. 12 + 4 stud_segments triangles per
// brick and visible stud. Validates the assembly first (InputError naming "assembly <name>").
TriangleMesh BuildDuploMesh(const DuploAssembly& assembly,
                            int stud_segments = kDuploDefaultStudSegments);

// A single brick of a catalogue type in its model frame (centred footprint, z = 0 at its bottom).
// An unknown type is an InputError.
TriangleMesh MakeDuploBrick(const std::string& type, const Rgb8& color,
                            int stud_segments = kDuploDefaultStudSegments);

// The soldier of the paper's "Soldier takes a Break" story (the same as
// configs/proxies/soldier.json): black boots, dark blue trousers, a red tunic (three 2x4 bricks
// laid along x), a light-nougat 2x2 head, a black 2x2 busby on it and a reddish-brown 1x2 rifle
// beside the head on the soldier's left (+x). 64 x 32 x 96 mm plus studs; the rifle breaks the
// left-right symmetry so that every pose is distinguishable by shape.
DuploAssembly SoldierProxy();

}  // namespace mmh::sim
