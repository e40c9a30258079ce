// A coloured triangle mesh with named morph targets as a glTF 2.0 binary (.glb), written with
// tinygltf: one scene, one node, one mesh of one primitive; POSITION, NORMAL, COLOR_0 (linear RGB,
// float) and 32-bit indices; each morph target a POSITION displacement (a sparse accessor: only the
// vertices it moves), its name in mesh.extras.targetNames (the convention three.js, Blender and
// Babylon.js read) and a default weight of 0. asset.extras carries `extras` (generator, source,
// licence notices).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/mesh/surface_nets.h"

namespace icef::mesh {

struct MorphTarget {
  std::string name;
  std::vector<Vec3f> displacements;  // [vertices]: the target's position minus the base
};

struct GlbMesh {
  std::string name = "avatar";
  TriangleMesh mesh;
  std::vector<Vec3f> normals;  // [vertices], unit
  std::vector<Vec3f> colors;   // [vertices], linear RGB in [0, 1]
  std::vector<MorphTarget> targets;
  nlohmann::json extras = nlohmann::json::object();  // asset.extras
};

// Writes the GLB to `path` atomically (a temporary file, then a rename). Errors: sizes that do not
// match the vertex count, non-finite values, an index out of range, a write that fails.
Status WriteGlb(const GlbMesh& glb, const std::filesystem::path& path);

// What a GLB holds, as read back by tinygltf (tests and `icef export`'s summary).
struct GlbSummary {
  size_t vertices = 0, triangles = 0;
  std::vector<std::string> target_names;
  std::vector<size_t> target_moved;  // per target: the vertices its sparse accessor moves
  nlohmann::json asset_extras;
};
Result<GlbSummary> ReadGlbSummary(const std::filesystem::path& path);

// The base mesh's vertex positions, read back.
Result<std::vector<Vec3f>> ReadGlbPositions(const std::filesystem::path& path);

// A morph target's displacement of every vertex, read back ([vertices], zeros where sparse).
Result<std::vector<Vec3f>> ReadGlbTarget(const std::filesystem::path& path, int target);

}  // namespace icef::mesh
