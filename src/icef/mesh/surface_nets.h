// Triangle meshes of a sampled scalar field's level set, and the small steps that make them
// presentable: surface nets (one vertex per grid cell the level set crosses, at the mean of the
// crossings on the cell's edges; one quad per crossed grid edge), keeping the large connected pieces,
// simplification to a triangle budget (meshoptimizer) and area-weighted vertex normals.
//
// Orientation: "inside" is where the field exceeds the level (a density); triangles wind
// counter-clockwise seen from outside, so their normals point out (toward lower values).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "icef/math/types.h"

namespace icef::mesh {

struct TriangleMesh {
  std::vector<Vec3f> positions;
  std::vector<std::array<uint32_t, 3>> triangles;

  std::string ToString() const;
};

// A scalar field on a regular grid: values[(k * dims[1] + j) * dims[0] + i] at origin + cell * (i, j, k).
struct ScalarGrid {
  std::array<int, 3> dims{0, 0, 0};
  Vec3f origin = Vec3f::Zero();
  float cell = 1;
  std::vector<float> values;

  float at(int i, int j, int k) const { return values[(static_cast<size_t>(k) * dims[1] + j) * dims[0] + i]; }
  Vec3f point(int i, int j, int k) const { return origin + cell * Vec3f(float(i), float(j), float(k)); }
};

// The level set {value = level} of the grid (grid.values.size() must be the product of dims, each
// dims >= 2). Deterministic; vertices in the order of their cells.
TriangleMesh SurfaceNets(const ScalarGrid& grid, float level);

// The mesh without the connected pieces (sharing vertices) that have fewer than min_fraction of the
// largest piece's triangles; unused vertices dropped, order kept.
TriangleMesh KeepLargePieces(const TriangleMesh& mesh, double min_fraction);

// The mesh simplified towards at most max_triangles (meshoptimizer's edge collapse, which keeps the
// border and the topology; it may stop above the budget), unused vertices dropped.
TriangleMesh Simplify(const TriangleMesh& mesh, size_t max_triangles);

// Area-weighted vertex normals, unit: where a vertex's triangles cancel (a pinch), one of their
// normals; +z at a vertex of no triangle with area.
std::vector<Vec3f> VertexNormals(const TriangleMesh& mesh);

}  // namespace icef::mesh
