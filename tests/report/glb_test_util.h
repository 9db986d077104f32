// Test oracles for .glb files: an independent minimal reader (the GLB container, the JSON chunk,
// float accessors, node and animation look-ups; written from the glTF 2.0 specification, not from
// the writer) and the Khronos glTF-Validator run through node.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/trajectory.h"
#include "tests/test_util.h"

namespace mmh::test_util {

struct Glb {
  nlohmann::json json;
  std::string bin;
};

inline std::uint32_t ReadU32(const std::string& bytes, std::size_t at) {
  std::uint32_t value = 0;
  for (int i = 0; i < 4; ++i) value |= std::uint32_t(std::uint8_t(bytes.at(at + i))) << (8 * i);
  return value;
}

// Parses the container; fails the test (and returns an empty Glb) on a malformed file.
inline Glb ParseGlb(const std::string& bytes) {
  Glb glb;
  EXPECT_GE(bytes.size(), 20u);
  if (bytes.size() < 20) return glb;
  EXPECT_EQ(ReadU32(bytes, 0), 0x46546C67u) << "magic";
  EXPECT_EQ(ReadU32(bytes, 4), 2u) << "version";
  EXPECT_EQ(ReadU32(bytes, 8), bytes.size()) << "length";
  const std::uint32_t json_length = ReadU32(bytes, 12);
  EXPECT_EQ(ReadU32(bytes, 16), 0x4E4F534Au) << "JSON chunk";
  glb.json = nlohmann::json::parse(bytes.substr(20, json_length));
  const std::size_t bin_at = 20 + json_length;
  if (bin_at < bytes.size()) {
    EXPECT_EQ(ReadU32(bytes, bin_at + 4), 0x004E4942u) << "BIN chunk";
    glb.bin = bytes.substr(bin_at + 8, ReadU32(bytes, bin_at));
  }
  return glb;
}

// The float values of an accessor (tightly packed float bufferViews, as glTF allows).
inline std::vector<double> AccessorFloats(const Glb& glb, int accessor_index) {
  const auto& accessor = glb.json["accessors"][accessor_index];
  EXPECT_EQ(accessor["componentType"], 5126);
  const auto& view = glb.json["bufferViews"][accessor["bufferView"].get<int>()];
  const std::string type = accessor["type"];
  const int components = type == "SCALAR" ? 1 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : 0;
  const std::size_t count = accessor["count"].get<std::size_t>() * components;
  const std::size_t offset =
      view.value("byteOffset", std::size_t{0}) + accessor.value("byteOffset", std::size_t{0});
  std::vector<double> values(count);
  for (std::size_t i = 0; i < count; ++i) {
    float f;
    std::memcpy(&f, glb.bin.data() + offset + 4 * i, 4);
    values[i] = f;
  }
  return values;
}

inline int NodeIndex(const Glb& glb, const std::string& name) {
  const auto& nodes = glb.json["nodes"];
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].value("name", "") == name) return static_cast<int>(i);
  }
  ADD_FAILURE() << "no node named " << name;
  return -1;
}

// The animated pose of node `name` in animation `animation` (parent_T_node in glTF's axes), with
// the timestamps restored from the animation's extras (mmh_time_origins_s, and the exact times
// mmh_frame_periods_s or mmh_times_s where present).
inline Trajectory AnimatedTrajectory(const Glb& glb, const std::string& animation,
                                     const std::string& name) {
  Trajectory out;
  const int node = NodeIndex(glb, name);
  for (const auto& a : glb.json["animations"]) {
    if (a["name"] != animation) continue;
    const double origin = a["extras"]["mmh_time_origins_s"][name].get<double>();
    std::vector<double> times, translations, rotations;
    for (const auto& channel : a["channels"]) {
      if (channel["target"]["node"] != node) continue;
      const auto& sampler = a["samplers"][channel["sampler"].get<int>()];
      EXPECT_EQ(sampler["interpolation"], "LINEAR");
      times = AccessorFloats(glb, sampler["input"]);
      if (channel["target"]["path"] == "translation") translations = AccessorFloats(glb, sampler["output"]);
      if (channel["target"]["path"] == "rotation") rotations = AccessorFloats(glb, sampler["output"]);
    }
    EXPECT_EQ(translations.size(), 3 * times.size());
    EXPECT_EQ(rotations.size(), 4 * times.size());
    for (std::size_t i = 0; i < times.size() && 4 * i + 3 < rotations.size() &&
                            3 * i + 2 < translations.size();
         ++i) {
      // Exact times from the extras where the writer put them (report/gltf_scene.h).
      const auto& extras = a["extras"];
      if (extras.contains("mmh_frame_periods_s") && extras["mmh_frame_periods_s"].contains(name)) {
        out.timestamps.push_back(origin + double(i) * extras["mmh_frame_periods_s"][name].get<double>());
      } else if (extras.contains("mmh_times_s") && extras["mmh_times_s"].contains(name)) {
        out.timestamps.push_back(origin + extras["mmh_times_s"][name][i].get<double>());
      } else {
        out.timestamps.push_back(origin + times[i]);
      }
      out.poses.push_back(Rigid3(
          Eigen::Quaterniond(rotations[4 * i + 3], rotations[4 * i], rotations[4 * i + 1],
                             rotations[4 * i + 2]),
          Eigen::Vector3d(translations[3 * i], translations[3 * i + 1], translations[3 * i + 2])));
    }
    return out;
  }
  ADD_FAILURE() << "no animation named " << animation;
  return out;
}

// The static pose (translation, rotation) of a node.
inline Rigid3 NodePose(const Glb& glb, const std::string& name) {
  const auto& node = glb.json["nodes"][NodeIndex(glb, name)];
  Rigid3 pose;
  if (node.contains("translation")) {
    const auto& t = node["translation"];
    pose.translation = Eigen::Vector3d(t[0].get<double>(), t[1].get<double>(), t[2].get<double>());
  }
  if (node.contains("rotation")) {
    const auto& r = node["rotation"];
    pose.rotation = Eigen::Quaterniond(r[3].get<double>(), r[0].get<double>(), r[1].get<double>(),
                                       r[2].get<double>());
  }
  return pose;
}

// Runs the Khronos glTF-Validator on `files`: every one must have 0 errors and 0 warnings.
inline void ExpectValidGltf(const std::vector<std::filesystem::path>& files) {
  std::string command = std::string("NODE_PATH='") + MMH_NODE_MODULES + "' node '" +
                        MMH_SOURCE_DIR + "/report/web/tools/validate.js'";
  for (const auto& file : files) command += " '" + file.string() + "'";
  command += " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  const int status = pclose(pipe);
  EXPECT_EQ(status, 0) << "glTF-Validator:\n" << output;
}

}  // namespace mmh::test_util
