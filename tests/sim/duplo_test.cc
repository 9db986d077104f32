// Tests of sim/primitives.h (closed surfaces, analytic volumes, outward faces) and sim/duplo.h
// (real Duplo dimensions, hidden studs, the JSON form and its errors, the shipped proxies).
#include "sim/duplo.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "core/error.h"
#include "sim/primitives.h"

namespace mmh::sim {
namespace {

using ::testing::HasSubstr;
using json = nlohmann::json;

constexpr Rgb8 kRed = {201, 26, 9};

// Volume of the regular n-gon prism inscribed in a cylinder.
double PrismVolume(double radius, double height, int segments) {
  return 0.5 * segments * std::sin(2 * std::numbers::pi / segments) * radius * radius * height;
}

// Every face's normal points away from `inside` (true for convex shapes around that point).
void ExpectOutwardFrom(const TriangleMesh& mesh, const Eigen::Vector3d& inside) {
  const auto normals = FaceNormals(mesh);
  for (int f = 0; f < mesh.face_count(); ++f) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) centroid += mesh.vertices.row(mesh.faces(f, k)).cast<double>();
    centroid /= 3;
    EXPECT_GT(normals.row(f).cast<double>().dot((centroid - inside).transpose()), 0)
        << "face " << f;
  }
}

// ---- Primitives ----

TEST(PrimitivesTest, BoxIsClosedCentredWithExactVolume) {
  const TriangleMesh box = MakeBox({0.2, 0.05, 0.1}, kRed);
  EXPECT_EQ(box.face_count(), 12);
  EXPECT_TRUE(IsClosed(box));
  EXPECT_NEAR(SignedVolume(box), 0.2 * 0.05 * 0.1, 1e-6 * 1e-3);
  ExpectOutwardFrom(box, Eigen::Vector3d::Zero());
  const Bounds3 b = ComputeBounds(box);
  EXPECT_NEAR(b.min.x(), -0.1, 1e-7);
  EXPECT_NEAR(b.max.z(), 0.05, 1e-7);
  EXPECT_EQ(box.face_colors(11, 0), 201);
}

TEST(PrimitivesTest, CylinderFrustumConeAreClosedWithAnalyticVolumes) {
  const TriangleMesh cylinder = MakeCylinder(0.0048, 0.0045, 16, kRed);
  EXPECT_TRUE(IsClosed(cylinder));
  EXPECT_EQ(cylinder.face_count(), 4 * 16);
  EXPECT_NEAR(SignedVolume(cylinder) / PrismVolume(0.0048, 0.0045, 16), 1.0, 1e-6);
  ExpectOutwardFrom(cylinder, {0, 0, 0.00225});
  const Bounds3 b = ComputeBounds(cylinder);
  EXPECT_NEAR(b.min.z(), 0.0, 1e-9);
  EXPECT_NEAR(b.max.z(), 0.0045, 1e-9);
  EXPECT_NEAR(b.max.x(), 0.0048, 1e-9);

  // Frustum: (h / 3) (A1 + A2 + sqrt(A1 A2)) with the polygons' areas.
  const int n = 12;
  const double a1 = 0.5 * n * std::sin(2 * std::numbers::pi / n) * 0.03 * 0.03;
  const double a2 = 0.5 * n * std::sin(2 * std::numbers::pi / n) * 0.02 * 0.02;
  const TriangleMesh frustum = MakeFrustum(0.03, 0.02, 0.1, n, kRed);
  EXPECT_TRUE(IsClosed(frustum));
  EXPECT_NEAR(SignedVolume(frustum) / (0.1 / 3 * (a1 + a2 + std::sqrt(a1 * a2))), 1.0, 1e-6);
  ExpectOutwardFrom(frustum, {0, 0, 0.05});

  const TriangleMesh cone = MakeCone(0.03, 0.1, n, kRed);
  EXPECT_TRUE(IsClosed(cone));
  EXPECT_EQ(cone.face_count(), 2 * n);
  EXPECT_NEAR(SignedVolume(cone) / (0.1 / 3 * a1), 1.0, 1e-6);
  ExpectOutwardFrom(cone, {0, 0, 0.02});
  // An upside-down cone (apex at the bottom) is closed and outward too.
  const TriangleMesh funnel = MakeFrustum(0.0, 0.03, 0.1, n, kRed);
  EXPECT_TRUE(IsClosed(funnel));
  EXPECT_NEAR(SignedVolume(funnel) / (0.1 / 3 * a1), 1.0, 1e-6);
}

TEST(PrimitivesTest, SphereAndCapsuleAreClosedAndNearTheirVolumes) {
  const TriangleMesh sphere = MakeSphere(0.05, 32, kRed);
  EXPECT_TRUE(IsClosed(sphere));
  EXPECT_NEAR(SignedVolume(sphere) / (4.0 / 3 * std::numbers::pi * 0.05 * 0.05 * 0.05), 1.0, 0.03);
  ExpectOutwardFrom(sphere, Eigen::Vector3d::Zero());

  const double r = 0.009;
  const double length = 0.04;
  const TriangleMesh capsule = MakeCapsule(r, length, 16, kRed);
  EXPECT_TRUE(IsClosed(capsule));
  EXPECT_EQ(capsule.face_count(), 16 * 4 * 4);
  const double exact = std::numbers::pi * r * r * length + 4.0 / 3 * std::numbers::pi * r * r * r;
  const double ratio = SignedVolume(capsule) / exact;
  EXPECT_LT(ratio, 1.0);  // inscribed polygons
  EXPECT_GT(ratio, 0.93);
  const Bounds3 b = ComputeBounds(capsule);
  EXPECT_NEAR(b.min.z(), -r, 1e-7);
  EXPECT_NEAR(b.max.z(), length + r, 1e-7);

  // Between two points: the axis follows them.
  const TriangleMesh between =
      MakeCapsuleBetween({0.1, 0.2, 0.3}, {0.1, 0.2 + length, 0.3}, r, 16, kRed);
  EXPECT_TRUE(IsClosed(between));
  EXPECT_NEAR(SignedVolume(between) / SignedVolume(capsule), 1.0, 1e-6);
  const Bounds3 c = ComputeBounds(between);
  EXPECT_NEAR(c.min.y(), 0.2 - r, 1e-7);
  EXPECT_NEAR(c.max.y(), 0.2 + length + r, 1e-7);
  EXPECT_NEAR(c.max.x(), 0.1 + r, 1e-6);
}

// ---- Duplo bricks and assemblies ----

TEST(DuploTest, TwoByTwoBrickHasRealDimensions) {
  const TriangleMesh brick = MakeDuploBrick("2x2", kDuploGreen);
  const Bounds3 b = ComputeBounds(brick);
  EXPECT_NEAR(b.max.x() - b.min.x(), 0.0318, 1e-7);
  EXPECT_NEAR(b.max.y() - b.min.y(), 0.0318, 1e-7);
  EXPECT_NEAR(b.max.z() - b.min.z(), 0.0192 + 0.0045, 1e-7);
  EXPECT_NEAR(b.min.z(), 0.0, 1e-9);
  EXPECT_NEAR(b.min.x(), -0.0159, 1e-7);  // centred footprint
  EXPECT_NEAR(b.max.y(), 0.0159, 1e-7);
  EXPECT_TRUE(IsClosed(brick));
  const double body = 0.0318 * 0.0318 * 0.0192;
  const double stud = PrismVolume(0.0048, 0.0045, 16);
  EXPECT_NEAR(SignedVolume(brick) / (body + 4 * stud), 1.0, 1e-6);
  EXPECT_EQ(brick.face_count(), 12 + 4 * 4 * 16);
  for (int f = 0; f < brick.face_count(); ++f) EXPECT_EQ(brick.face_colors(f, 1), kDuploGreen[1]);
}

TEST(DuploTest, FootprintsFollowTypeAndRotation) {
  const TriangleMesh along_y = MakeDuploBrick("2x4", kRed);
  const Bounds3 b = ComputeBounds(along_y);
  EXPECT_NEAR(b.max.x() - b.min.x(), 2 * 0.016 - 0.0002, 1e-7);
  EXPECT_NEAR(b.max.y() - b.min.y(), 4 * 0.016 - 0.0002, 1e-7);
  DuploBrick brick;
  brick.type = "2x4";
  brick.rotated = true;
  EXPECT_EQ(DuploFootprint(brick), Eigen::Vector2i(4, 2));
  brick.rotated = false;
  EXPECT_EQ(DuploFootprint(brick), Eigen::Vector2i(2, 4));
  for (const auto& type : DuploBrickTypes()) {
    const TriangleMesh mesh = MakeDuploBrick(type.name, kRed, 8);
    EXPECT_EQ(mesh.face_count(), 12 + type.studs_x * type.studs_y * 4 * 8) << type.name;
  }
  EXPECT_TRUE(FindDuploBrickType("2x2"));
  EXPECT_TRUE(FindDuploBrickType("2x4"));
  EXPECT_THROW(MakeDuploBrick("3x3", kRed), InputError);
}

DuploAssembly Stack(int count) {
  DuploAssembly assembly;
  for (int level = 0; level < count; ++level) {
    assembly.bricks.push_back({"2x2", 0, 0, level, false, kRed});
  }
  return assembly;
}

TEST(DuploTest, StackedBricksHideTheStudsBeneath) {
  const TriangleMesh one = BuildDuploMesh(Stack(1));
  const TriangleMesh two = BuildDuploMesh(Stack(2));
  const int stud_faces = 4 * 16;
  EXPECT_EQ(one.face_count(), 12 + 4 * stud_faces);
  EXPECT_EQ(two.face_count(), 2 * 12 + 4 * stud_faces);  // 4 studs visible, not 8
  EXPECT_TRUE(IsClosed(two));
  const Bounds3 b = ComputeBounds(two);
  EXPECT_NEAR(b.max.z(), 2 * 0.0192 + 0.0045, 1e-7);
  // No stud geometry between the bricks: nothing strictly inside (0.0192, 0.0192 + stud height)
  // except brick walls, whose vertices are at the layer boundaries.
  for (int v = 0; v < two.vertex_count(); ++v) {
    const float z = two.vertices(v, 2);
    EXPECT_FALSE(z > 0.0193f && z < 0.0384f - 1e-4f) << "vertex " << v << " at z " << z;
  }

  // A 2x2 on one half of a 2x4: the 2x4 keeps the 4 studs of its uncovered half.
  DuploAssembly half;
  half.bricks = {{"2x4", 0, 0, 0, false, kRed}, {"2x2", 0, 2, 1, false, kDuploGreen}};
  EXPECT_EQ(BuildDuploMesh(half).face_count(), 2 * 12 + (4 + 4) * stud_faces);
}

TEST(DuploTest, ModelFrameIsCentredOnTheFootprint) {
  DuploAssembly l_shape;  // cells x 5..8 at the bottom, a 2x2 on its right end
  l_shape.bricks = {{"2x4", 5, -3, 0, true, kRed}, {"2x2", 7, -3, 1, false, kRed}};
  const Bounds3 b = ComputeBounds(BuildDuploMesh(l_shape));
  EXPECT_NEAR(b.min.x(), -0.0319, 1e-7);
  EXPECT_NEAR(b.max.x(), 0.0319, 1e-7);
  EXPECT_NEAR(b.min.y(), -0.0159, 1e-7);
  EXPECT_NEAR(b.max.y(), 0.0159, 1e-7);
  EXPECT_NEAR(b.min.z(), 0.0, 1e-9);
  // The top stud sits over the right half (+x).
  EXPECT_NEAR(b.max.z(), 2 * 0.0192 + 0.0045, 1e-7);
}

TEST(DuploTest, SoldierIsValidAndMatchesItsJsonFile) {
  const DuploAssembly soldier = SoldierProxy();
  EXPECT_NO_THROW(ValidateDuploAssembly(soldier, "soldier"));
  EXPECT_GE(soldier.bricks.size(), 4u);
  EXPECT_LE(soldier.bricks.size(), 6u);
  const DuploAssembly file = LoadDuploAssembly(MMH_SOURCE_DIR "/configs/proxies/soldier.json");
  EXPECT_EQ(DuploAssemblyToJson(file), DuploAssemblyToJson(soldier));
  const TriangleMesh mesh = BuildDuploMesh(soldier);
  EXPECT_TRUE(IsClosed(mesh));
  const Bounds3 b = ComputeBounds(mesh);
  EXPECT_NEAR(b.max.x() - b.min.x(), 4 * 0.016 - 0.0002, 1e-7);
  EXPECT_NEAR(b.max.y() - b.min.y(), 2 * 0.016 - 0.0002, 1e-7);
  EXPECT_NEAR(b.max.z(), 5 * 0.0192 + 0.0045, 1e-7);
  EXPECT_LT(mesh.face_count(), 2000);
}

TEST(DuploTest, MarioJsonLoadsAndBuilds) {
  const DuploAssembly mario = LoadDuploAssembly(MMH_SOURCE_DIR "/configs/proxies/mario.json");
  EXPECT_EQ(mario.name, "mario");
  const TriangleMesh mesh = BuildDuploMesh(mario);
  EXPECT_TRUE(IsClosed(mesh));
  EXPECT_GT(SignedVolume(mesh), 0);
  EXPECT_LT(mesh.face_count(), 2000);
}

TEST(DuploTest, JsonRoundTripKeepsEveryField) {
  DuploAssembly assembly;
  assembly.name = "test";
  assembly.description = "two bricks";
  assembly.bricks = {{"2x4", -2, 3, 0, true, {1, 2, 3}}, {"1x2", -2, 3, 1, false, kDuploGreen}};
  const json j = DuploAssemblyToJson(assembly);
  EXPECT_EQ(j["bricks"][1]["color"], "green");
  EXPECT_EQ(j["bricks"][0]["color"], json::array({1, 2, 3}));
  const DuploAssembly back = ParseDuploAssembly(j, "test");
  EXPECT_EQ(DuploAssemblyToJson(back), j);
  EXPECT_EQ(back.bricks[0].x, -2);
  EXPECT_TRUE(back.bricks[0].rotated);
  EXPECT_EQ(back.bricks[0].color, (Rgb8{1, 2, 3}));
}

// Parses `text` expecting an InputError; returns its message.
std::string ParseError(const std::string& text) {
  try {
    ParseDuploAssembly(json::parse(text), "proxy");
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted " << text;
  return "";
}

TEST(DuploTest, ErrorsNameTheBrickTheFieldAndTheValue) {
  const std::string ok = R"({"type": "2x2", "at": [0, 0, 0], "color": "red"})";
  auto with = [&](const std::string& second) {
    return R"({"bricks": [)" + ok + ", " + second + "]}";
  };
  std::string e = ParseError(with(R"({"type": "2x5", "at": [0, 0, 1], "color": "red"})"));
  EXPECT_THAT(e, HasSubstr("proxy.bricks[1].type"));
  EXPECT_THAT(e, HasSubstr("\"2x5\""));
  EXPECT_THAT(e, HasSubstr("2x4"));

  e = ParseError(with(R"({"type": "4x2", "at": [0, 0, 1], "color": "red"})"));
  EXPECT_THAT(e, HasSubstr("did you mean \"2x4\" with \"rotated\": true"));

  e = ParseError(with(R"({"type": "2x2", "at": [0, 0, 1], "color": "gren"})"));
  EXPECT_THAT(e, HasSubstr("proxy.bricks[1].color"));
  EXPECT_THAT(e, HasSubstr("\"gren\""));
  EXPECT_THAT(e, HasSubstr("did you mean \"green\""));

  e = ParseError(with(R"({"type": "2x2", "at": [0, 0, 1], "color": [255, 0, 256]})"));
  EXPECT_THAT(e, HasSubstr("proxy.bricks[1].color: got [255,0,256]"));

  e = ParseError(with(R"({"type": "2x2", "at": [0, 0, 1], "colour": "red"})"));
  EXPECT_THAT(e, HasSubstr("proxy.bricks[1].colour"));
  EXPECT_THAT(e, HasSubstr("did you mean 'color'"));

  e = ParseError(with(R"({"type": "2x2", "at": [0, 0.5, 1], "color": "red"})"));
  EXPECT_THAT(e, HasSubstr("proxy.bricks[1].at: got [0,0.5,1]"));

  e = ParseError(with(R"({"type": "2x2", "at": [0, 0, -1], "color": "red"})"));
  EXPECT_THAT(e, HasSubstr("proxy.bricks[1].at"));
  EXPECT_THAT(e, HasSubstr("level in [0, 100]"));

  e = ParseError(with(R"({"type": "2x2", "at": [0, 0, 1], "rotated": "yes", "color": "red"})"));
  EXPECT_THAT(e, HasSubstr("proxy.bricks[1].rotated: got \"yes\", expected true or false"));

  e = ParseError(with(R"({"type": "2x2", "at": [0, 0, 1]})"));
  EXPECT_THAT(e, HasSubstr("proxy.bricks[1].color"));
  EXPECT_THAT(e, HasSubstr("missing"));

  e = ParseError(with(R"({"type": 22, "at": [0, 0, 1], "color": "red"})"));
  EXPECT_THAT(e, HasSubstr("proxy.bricks[1].type: got 22"));

  e = ParseError(with("[1, 2]"));
  EXPECT_THAT(e, HasSubstr("proxy.bricks[1]: got [1,2]"));
}

TEST(DuploTest, EmptyOverlappingAndFloatingAssembliesAreRejected) {
  EXPECT_THAT(ParseError(R"({"bricks": []})"),
              HasSubstr("proxy.bricks: got [], expected a non-empty"));
  EXPECT_THAT(ParseError(R"({"brick": []})"), HasSubstr("did you mean 'bricks'"));
  EXPECT_THAT(ParseError(R"({"name": "x"})"), HasSubstr("proxy.bricks"));
  EXPECT_THAT(ParseError(R"([1])"), HasSubstr("proxy: got [1]"));

  std::string e = ParseError(R"({"bricks": [
      {"type": "2x4", "at": [0, 0, 0], "color": "red"},
      {"type": "2x2", "at": [1, 3, 0], "color": "blue"}]})");
  EXPECT_THAT(e, HasSubstr("proxy.bricks[1]"));
  EXPECT_THAT(e, HasSubstr("cell [1, 3, 0]"));
  EXPECT_THAT(e, HasSubstr("bricks[0]"));

  e = ParseError(R"({"bricks": [
      {"type": "2x2", "at": [0, 0, 0], "color": "red"},
      {"type": "2x2", "at": [0, 0, 1], "color": "red"},
      {"type": "2x2", "at": [2, 0, 2], "color": "red"}]})");
  EXPECT_THAT(e, HasSubstr("proxy.bricks[2]"));
  EXPECT_THAT(e, HasSubstr("[2, 0, 2]"));
  EXPECT_THAT(e, HasSubstr("nothing beneath"));

  // Touching diagonally by one stud is enough support.
  EXPECT_NO_THROW(ParseDuploAssembly(json::parse(R"({"bricks": [
      {"type": "2x2", "at": [0, 0, 0], "color": "red"},
      {"type": "2x2", "at": [1, 1, 1], "color": "red"}]})"),
                                     "proxy"));
}

TEST(DuploTest, LoadErrorsNameTheFile) {
  try {
    LoadDuploAssembly(MMH_SOURCE_DIR "/configs/proxies/no_such_proxy.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no_such_proxy.json"));
  }
}

}  // namespace
}  // namespace mmh::sim
