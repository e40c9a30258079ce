#include "icef/mesh/glb.h"

#include <gtest/gtest.h>

#include <fstream>

namespace icef::mesh {
namespace {

GlbMesh Tetrahedron() {
  GlbMesh glb;
  glb.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  glb.mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  glb.normals = VertexNormals(glb.mesh);
  glb.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5f, 0.5f, 0.5f}};
  glb.targets.push_back({"jawOpen", {{0, -0.1f, 0}, {0, 0, 0}, {0, 0, 0}, {0.01f, 0, 0.02f}}});
  glb.targets.push_back({"eyeBlinkLeft", std::vector<Vec3f>(4, Vec3f::Zero())});
  glb.extras = {{"source", "test"}, {"licence", "MIT"}};
  return glb;
}

TEST(Glb, RoundTripKeepsTheMeshTargetsAndExtras) {
  const auto path = std::filesystem::path(::testing::TempDir()) / "glb_round_trip.glb";
  const GlbMesh glb = Tetrahedron();
  ASSERT_TRUE(WriteGlb(glb, path).ok());
  const Result<GlbSummary> s = ReadGlbSummary(path);
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->vertices, 4u);
  EXPECT_EQ(s->triangles, 4u);
  EXPECT_EQ(s->target_names, (std::vector<std::string>{"jawOpen", "eyeBlinkLeft"}));
  EXPECT_EQ(s->target_moved, (std::vector<size_t>{2, 0}));
  EXPECT_EQ(s->asset_extras.at("source"), "test");
  for (int t = 0; t < 2; ++t) {
    const Result<std::vector<Vec3f>> d = ReadGlbTarget(path, t);
    ASSERT_TRUE(d.ok()) << d.status().message();
    EXPECT_EQ(*d, glb.targets[t].displacements);
  }
  // The binary container: magic, version 2, the length in the header is the file's.
  std::ifstream in(path, std::ios::binary);
  uint32_t header[3];
  in.read(reinterpret_cast<char*>(header), sizeof(header));
  EXPECT_EQ(header[0], 0x46546C67u);
  EXPECT_EQ(header[1], 2u);
  EXPECT_EQ(header[2], std::filesystem::file_size(path));
  std::filesystem::remove(path);
}

TEST(Glb, BadInputIsRefusedAndLeavesTheOldFile) {
  const auto path = std::filesystem::path(::testing::TempDir()) / "glb_bad.glb";
  { std::ofstream(path) << "old"; }
  GlbMesh glb = Tetrahedron();
  glb.colors.pop_back();
  EXPECT_FALSE(WriteGlb(glb, path).ok());
  glb = Tetrahedron();
  glb.targets[0].displacements[1].x() = NAN;
  const Status nan = WriteGlb(glb, path);
  EXPECT_NE(nan.message().find("jawOpen"), std::string::npos) << nan.message();
  glb = Tetrahedron();
  glb.mesh.triangles[0][0] = 9;
  EXPECT_FALSE(WriteGlb(glb, path).ok());
  std::ifstream in(path);
  std::string text;
  in >> text;
  EXPECT_EQ(text, "old");
  EXPECT_FALSE(ReadGlbSummary(path).ok());
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace icef::mesh
