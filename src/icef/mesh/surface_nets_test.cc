#include "icef/mesh/surface_nets.h"

#include <gtest/gtest.h>

#include <map>
#include <utility>

namespace icef::mesh {
namespace {

// radius - |x - centre| sampled on an n^3 grid over [-1, 1]^3 (inside: positive).
ScalarGrid Ball(int n, const Vec3f& centre, float radius, ScalarGrid grid = {}) {
  if (grid.values.empty()) {
    grid.dims = {n, n, n};
    grid.origin = Vec3f::Constant(-1.f);
    grid.cell = 2.f / static_cast<float>(n - 1);
    grid.values.assign(static_cast<size_t>(n) * n * n, -1e9f);
  }
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        float& v = grid.values[(static_cast<size_t>(k) * n + j) * n + i];
        v = std::max(v, radius - (grid.point(i, j, k) - centre).norm());
      }
  return grid;
}

TEST(SurfaceNets, ASphereIsClosedOutwardAndOnTheLevelSet) {
  const ScalarGrid grid = Ball(40, Vec3f::Zero(), 0.6f);
  const TriangleMesh mesh = SurfaceNets(grid, 0.f);
  ASSERT_GT(mesh.triangles.size(), 1000u);
  for (const Vec3f& p : mesh.positions) EXPECT_NEAR(p.norm(), 0.6f, 0.1f * grid.cell);
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (const auto& t : mesh.triangles) {
    const Vec3f a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
    EXPECT_GT((b - a).cross(c - a).dot(a + b + c), 0.f) << "a triangle faces inwards";
    for (int m = 0; m < 3; ++m) ++directed[{t[m], t[(m + 1) % 3]}];
  }
  // Closed and consistently wound: every directed edge once, and its reverse once.
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u);
  }
  for (const Vec3f& n : VertexNormals(mesh)) EXPECT_NEAR(n.norm(), 1.f, 1e-5f);
}

TEST(SurfaceNets, SmallPiecesGoAndSimplifyKeepsTheShape) {
  ScalarGrid grid = Ball(48, Vec3f(-0.3f, 0, 0), 0.5f);
  grid = Ball(48, Vec3f(0.8f, 0.8f, 0.8f), 0.1f, std::move(grid));
  const TriangleMesh both = SurfaceNets(grid, 0.f);
  const TriangleMesh big = KeepLargePieces(both, 0.1);
  EXPECT_LT(big.triangles.size(), both.triangles.size());
  for (const Vec3f& p : big.positions) EXPECT_NEAR((p - Vec3f(-0.3f, 0, 0)).norm(), 0.5f, 0.1f * grid.cell);
  EXPECT_EQ(KeepLargePieces(both, 0.0).triangles.size(), both.triangles.size());
  const TriangleMesh small = Simplify(big, 1000);
  EXPECT_LE(small.triangles.size(), 1000u);
  EXPECT_GT(small.triangles.size(), 500u);
  for (const Vec3f& p : small.positions) EXPECT_NEAR((p - Vec3f(-0.3f, 0, 0)).norm(), 0.5f, 0.03f);
  EXPECT_EQ(Simplify(big, big.triangles.size()).triangles, big.triangles);
}

}  // namespace
}  // namespace icef::mesh
