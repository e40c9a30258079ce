#include "icef/mesh/surface_nets.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <numeric>
#include <sstream>

#include "icef/core/status.h"

namespace icef::mesh {

namespace {

constexpr uint32_t kNone = UINT32_MAX;

// The 12 edges of a cell as pairs of corners; corner c is at offset (c & 1, (c >> 1) & 1, c >> 2).
constexpr int kCellEdges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                   {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

uint32_t Find(std::vector<uint32_t>& parent, uint32_t v) {
  while (parent[v] != v) v = parent[v] = parent[parent[v]];
  return v;
}

// The triangles `kept` over the vertices they use, which keep their order.
TriangleMesh Compact(const std::vector<Vec3f>& positions, const std::vector<std::array<uint32_t, 3>>& kept) {
  std::vector<uint32_t> remap(positions.size(), kNone);
  for (const auto& t : kept)
    for (uint32_t v : t) remap[v] = 0;
  TriangleMesh out;
  for (size_t v = 0; v < positions.size(); ++v) {
    if (remap[v] == kNone) continue;
    remap[v] = static_cast<uint32_t>(out.positions.size());
    out.positions.push_back(positions[v]);
  }
  out.triangles.reserve(kept.size());
  for (const auto& t : kept) out.triangles.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
  return out;
}

}  // namespace

std::string TriangleMesh::ToString() const {
  std::ostringstream os;
  os << "TriangleMesh(vertices=" << positions.size() << ", triangles=" << triangles.size() << ")";
  return os.str();
}

TriangleMesh SurfaceNets(const ScalarGrid& grid, float level) {
  const auto [nx, ny, nz] = grid.dims;
  ICEF_CHECK(nx >= 2 && ny >= 2 && nz >= 2, "SurfaceNets: a grid of at least 2 points per axis");
  ICEF_CHECK(grid.values.size() == static_cast<size_t>(nx) * ny * nz, "SurfaceNets: values do not fill dims");
  const auto inside = [&](int i, int j, int k) { return grid.at(i, j, k) > level; };
  const auto cell_index = [&](int i, int j, int k) {
    return (static_cast<size_t>(k) * (ny - 1) + j) * (nx - 1) + i;
  };
  TriangleMesh mesh;
  std::vector<uint32_t> vertex_of_cell(static_cast<size_t>(nx - 1) * (ny - 1) * (nz - 1), kNone);
  for (int k = 0; k + 1 < nz; ++k) {
    for (int j = 0; j + 1 < ny; ++j) {
      for (int i = 0; i + 1 < nx; ++i) {
        float v[8];
        int count = 0;
        for (int c = 0; c < 8; ++c) {
          v[c] = grid.at(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
          count += v[c] > level;
        }
        if (count == 0 || count == 8) continue;
        Vec3f sum = Vec3f::Zero();
        int crossings = 0;
        for (const auto& [a, b] : kCellEdges) {
          if ((v[a] > level) == (v[b] > level)) continue;
          const float t = (level - v[a]) / (v[b] - v[a]);
          const Vec3f pa(float(a & 1), float((a >> 1) & 1), float(a >> 2));
          const Vec3f pb(float(b & 1), float((b >> 1) & 1), float(b >> 2));
          sum += pa + t * (pb - pa);
          ++crossings;
        }
        vertex_of_cell[cell_index(i, j, k)] = static_cast<uint32_t>(mesh.positions.size());
        mesh.positions.push_back(grid.point(i, j, k) + grid.cell * (sum / static_cast<float>(crossings)));
      }
    }
  }
  // A quad per grid edge whose ends differ, joining the four cells around it; for the edge along
  // axis a from p, the cells p - e_b - e_c, p - e_c, p, p - e_b ((a, b, c) cyclic) go
  // counter-clockwise seen from +a: the quad faces +a when p is inside (the field falls along +a).
  const int n[3] = {nx, ny, nz};
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const int p[3] = {i, j, k};
        for (int a = 0; a < 3; ++a) {
          const int b = (a + 1) % 3, c = (a + 2) % 3;
          if (p[a] + 1 >= n[a] || p[b] < 1 || p[c] < 1 || p[b] + 1 >= n[b] || p[c] + 1 >= n[c]) continue;
          int q[3] = {i, j, k};
          ++q[a];
          const bool in = inside(i, j, k);
          if (in == inside(q[0], q[1], q[2])) continue;
          uint32_t quad[4];
          const int db[4] = {-1, 0, 0, -1}, dc[4] = {-1, -1, 0, 0};
          for (int m = 0; m < 4; ++m) {
            int cell[3] = {i, j, k};
            cell[b] += db[m];
            cell[c] += dc[m];
            quad[m] = vertex_of_cell[cell_index(cell[0], cell[1], cell[2])];
          }
          if (!in) std::swap(quad[1], quad[3]);
          // Split along the shorter diagonal.
          const float d02 = (mesh.positions[quad[0]] - mesh.positions[quad[2]]).squaredNorm();
          const float d13 = (mesh.positions[quad[1]] - mesh.positions[quad[3]]).squaredNorm();
          if (d02 <= d13) {
            mesh.triangles.push_back({quad[0], quad[1], quad[2]});
            mesh.triangles.push_back({quad[0], quad[2], quad[3]});
          } else {
            mesh.triangles.push_back({quad[0], quad[1], quad[3]});
            mesh.triangles.push_back({quad[1], quad[2], quad[3]});
          }
        }
      }
    }
  }
  return mesh;
}

TriangleMesh KeepLargePieces(const TriangleMesh& mesh, double min_fraction) {
  std::vector<uint32_t> parent(mesh.positions.size());
  std::iota(parent.begin(), parent.end(), 0u);
  for (const auto& t : mesh.triangles) {
    for (int m = 1; m < 3; ++m) {
      const uint32_t a = Find(parent, t[0]), b = Find(parent, t[m]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::vector<size_t> size(mesh.positions.size(), 0);
  for (const auto& t : mesh.triangles) ++size[Find(parent, t[0])];
  const size_t largest = size.empty() ? 0 : *std::max_element(size.begin(), size.end());
  std::vector<std::array<uint32_t, 3>> kept;
  for (const auto& t : mesh.triangles)
    if (static_cast<double>(size[Find(parent, t[0])]) >= min_fraction * static_cast<double>(largest))
      kept.push_back(t);
  return Compact(mesh.positions, kept);
}

TriangleMesh Simplify(const TriangleMesh& mesh, size_t max_triangles) {
  if (mesh.triangles.size() <= max_triangles) return mesh;
  std::vector<uint32_t> indices(3 * mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int m = 0; m < 3; ++m) indices[3 * t + m] = mesh.triangles[t][m];
  std::vector<uint32_t> out(indices.size());
  const size_t count =
      meshopt_simplify(out.data(), indices.data(), indices.size(), mesh.positions.data()->data(),
                       mesh.positions.size(), sizeof(Vec3f), 3 * max_triangles, 1.f);
  std::vector<std::array<uint32_t, 3>> kept(count / 3);
  for (size_t t = 0; t < kept.size(); ++t) kept[t] = {out[3 * t], out[3 * t + 1], out[3 * t + 2]};
  return Compact(mesh.positions, kept);
}

std::vector<Vec3f> VertexNormals(const TriangleMesh& mesh) {
  std::vector<Vec3f> normals(mesh.positions.size(), Vec3f::Zero()), any(mesh.positions.size(), Vec3f::Zero());
  for (const auto& t : mesh.triangles) {
    const Vec3f& a = mesh.positions[t[0]];
    const Vec3f n = (mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a);  // twice the area
    const float norm = n.norm();
    for (uint32_t v : t) {
      normals[v] += n;
      if (any[v] == Vec3f::Zero() && norm > 0.f) any[v] = n / norm;
    }
  }
  for (size_t v = 0; v < normals.size(); ++v) {
    const float norm = normals[v].norm();
    if (norm > 1e-12f) {
      normals[v] /= norm;
    } else {
      normals[v] = any[v] != Vec3f::Zero() ? any[v] : Vec3f::UnitZ();
    }
  }
  return normals;
}

}  // namespace icef::mesh
