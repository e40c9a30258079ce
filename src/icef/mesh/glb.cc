#include "icef/mesh/glb.h"

#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <sstream>

#include "icef/io/atomic_file.h"

namespace icef::mesh {

namespace {

// Appends `bytes` to the buffer (4-byte aligned) as a new buffer view; returns its index.
int AddView(tinygltf::Model& model, const void* bytes, size_t size, int target) {
  std::vector<unsigned char>& data = model.buffers[0].data;
  data.resize((data.size() + 3) & ~size_t{3});
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = size;
  view.target = target;
  const auto* p = static_cast<const unsigned char*>(bytes);
  data.insert(data.end(), p, p + size);
  model.bufferViews.push_back(view);
  return static_cast<int>(model.bufferViews.size() - 1);
}

// A float VEC3 accessor over `values` (a view of its own), with min and max when `bounds`.
int AddVec3(tinygltf::Model& model, const std::vector<Vec3f>& values, bool bounds) {
  tinygltf::Accessor a;
  a.bufferView = AddView(model, values.data(), values.size() * sizeof(Vec3f), TINYGLTF_TARGET_ARRAY_BUFFER);
  a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  a.type = TINYGLTF_TYPE_VEC3;
  a.count = values.size();
  if (bounds) {
    Vec3f lo = Vec3f::Constant(INFINITY), hi = Vec3f::Constant(-INFINITY);
    for (const Vec3f& v : values) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    a.minValues = {lo.x(), lo.y(), lo.z()};
    a.maxValues = {hi.x(), hi.y(), hi.z()};
  }
  model.accessors.push_back(a);
  return static_cast<int>(model.accessors.size() - 1);
}

// A morph target's POSITION accessor: sparse over the vertices it moves (none: an accessor
// without a view, which glTF reads as zeros). min/max of every vertex's displacement.
int AddTarget(tinygltf::Model& model, const MorphTarget& target) {
  std::vector<uint32_t> moved;
  std::vector<Vec3f> values;
  Vec3f lo = Vec3f::Zero(), hi = Vec3f::Zero();
  for (size_t v = 0; v < target.displacements.size(); ++v) {
    const Vec3f& d = target.displacements[v];
    if (d == Vec3f::Zero()) continue;
    moved.push_back(static_cast<uint32_t>(v));
    values.push_back(d);
    lo = lo.cwiseMin(d), hi = hi.cwiseMax(d);
  }
  tinygltf::Accessor a;
  a.bufferView = -1;
  a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  a.type = TINYGLTF_TYPE_VEC3;
  a.count = target.displacements.size();
  a.minValues = {lo.x(), lo.y(), lo.z()};
  a.maxValues = {hi.x(), hi.y(), hi.z()};
  a.sparse.isSparse = false;
  if (!moved.empty()) {
    a.sparse.isSparse = true;
    a.sparse.count = static_cast<int>(moved.size());
    a.sparse.indices.bufferView = AddView(model, moved.data(), moved.size() * sizeof(uint32_t), 0);
    a.sparse.indices.byteOffset = 0;
    a.sparse.indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    a.sparse.values.bufferView = AddView(model, values.data(), values.size() * sizeof(Vec3f), 0);
    a.sparse.values.byteOffset = 0;
  }
  model.accessors.push_back(a);
  return static_cast<int>(model.accessors.size() - 1);
}

tinygltf::Value ToValue(const nlohmann::json& j) {
  if (j.is_object()) {
    tinygltf::Value::Object o;
    for (const auto& [k, v] : j.items()) o[k] = ToValue(v);
    return tinygltf::Value(o);
  }
  if (j.is_array()) {
    tinygltf::Value::Array a;
    for (const auto& v : j) a.push_back(ToValue(v));
    return tinygltf::Value(a);
  }
  if (j.is_boolean()) return tinygltf::Value(j.get<bool>());
  if (j.is_number_integer()) return tinygltf::Value(j.get<int>());
  if (j.is_number()) return tinygltf::Value(j.get<double>());
  if (j.is_string()) return tinygltf::Value(j.get<std::string>());
  return {};
}

nlohmann::json ToJson(const tinygltf::Value& v) {
  if (v.IsObject()) {
    nlohmann::json o = nlohmann::json::object();
    for (const std::string& k : v.Keys()) o[k] = ToJson(v.Get(k));
    return o;
  }
  if (v.IsArray()) {
    nlohmann::json a = nlohmann::json::array();
    for (size_t i = 0; i < v.ArrayLen(); ++i) a.push_back(ToJson(v.Get(static_cast<int>(i))));
    return a;
  }
  if (v.IsBool()) return v.Get<bool>();
  if (v.IsInt()) return v.Get<int>();
  if (v.IsNumber()) return v.GetNumberAsDouble();
  if (v.IsString()) return v.Get<std::string>();
  return nullptr;
}

Status Validate(const GlbMesh& glb) {
  const size_t n = glb.mesh.positions.size();
  const auto finite = [](const std::vector<Vec3f>& values) {
    for (const Vec3f& v : values)
      if (!v.allFinite()) return false;
    return true;
  };
  if (n == 0 || glb.mesh.triangles.empty()) return Status::Error("WriteGlb: an empty mesh");
  if (glb.normals.size() != n || glb.colors.size() != n)
    return Status::Error("WriteGlb: normals or colours do not match the " + std::to_string(n) + " vertices");
  if (!finite(glb.mesh.positions) || !finite(glb.normals) || !finite(glb.colors))
    return Status::Error("WriteGlb: non-finite positions, normals or colours");
  for (const auto& t : glb.mesh.triangles)
    for (uint32_t v : t)
      if (v >= n) return Status::Error("WriteGlb: a triangle index out of range");
  for (const MorphTarget& target : glb.targets) {
    if (target.name.empty()) return Status::Error("WriteGlb: a morph target without a name");
    if (target.displacements.size() != n || !finite(target.displacements))
      return Status::Error("WriteGlb: morph target " + target.name +
                           " does not match the vertices or is not finite");
  }
  return Status::Ok();
}

Result<tinygltf::Model> LoadGlb(const std::filesystem::path& path) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  if (!loader.LoadBinaryFromFile(&model, &err, &warn, path.string()))
    return Status::Error(path.string() + ": not a readable glTF binary: " + err);
  if (model.meshes.size() != 1 || model.meshes[0].primitives.size() != 1)
    return Status::Error(path.string() + ": expected one mesh of one primitive");
  return model;
}

}  // namespace

Status WriteGlb(const GlbMesh& glb, const std::filesystem::path& path) {
  ICEF_RETURN_IF_ERROR(Validate(glb));
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "icef export";
  model.asset.extras = ToValue(glb.extras);
  model.buffers.emplace_back();
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  primitive.attributes["POSITION"] = AddVec3(model, glb.mesh.positions, true);
  primitive.attributes["NORMAL"] = AddVec3(model, glb.normals, false);
  primitive.attributes["COLOR_0"] = AddVec3(model, glb.colors, false);
  {
    tinygltf::Accessor a;
    a.bufferView = AddView(model, glb.mesh.triangles.data(), glb.mesh.triangles.size() * 3 * sizeof(uint32_t),
                           TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    a.type = TINYGLTF_TYPE_SCALAR;
    a.count = 3 * glb.mesh.triangles.size();
    model.accessors.push_back(a);
    primitive.indices = static_cast<int>(model.accessors.size() - 1);
  }
  tinygltf::Mesh mesh;
  mesh.name = glb.name;
  tinygltf::Value::Array names;
  for (const MorphTarget& target : glb.targets) {
    primitive.targets.push_back({{"POSITION", AddTarget(model, target)}});
    mesh.weights.push_back(0.0);
    names.emplace_back(target.name);
  }
  if (!glb.targets.empty())
    mesh.extras = tinygltf::Value(tinygltf::Value::Object{{"targetNames", tinygltf::Value(names)}});
  tinygltf::Material material;
  material.name = "baked";
  material.doubleSided = false;
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 1.0;
  model.materials.push_back(material);
  primitive.material = 0;
  mesh.primitives.push_back(primitive);
  model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.mesh = 0;
  node.name = glb.name;
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes = {0};
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  model.buffers[0].data.resize((model.buffers[0].data.size() + 3) & ~size_t{3});
  std::ostringstream bytes;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, bytes, false, true))
    return Status::Error(path.string() + ": tinygltf could not write the GLB");
  return WriteFileAtomic(path, bytes.str());
}

Result<GlbSummary> ReadGlbSummary(const std::filesystem::path& path) {
  ICEF_ASSIGN_OR_RETURN(tinygltf::Model model, LoadGlb(path));
  const tinygltf::Primitive& p = model.meshes[0].primitives[0];
  GlbSummary s;
  s.vertices = model.accessors.at(p.attributes.at("POSITION")).count;
  s.triangles = model.accessors.at(p.indices).count / 3;
  const tinygltf::Value& names = model.meshes[0].extras.Get("targetNames");
  for (size_t t = 0; t < p.targets.size(); ++t) {
    s.target_names.push_back(names.IsArray() ? names.Get(static_cast<int>(t)).Get<std::string>() : "");
    const tinygltf::Accessor& a = model.accessors.at(p.targets[t].at("POSITION"));
    s.target_moved.push_back(a.sparse.isSparse ? static_cast<size_t>(a.sparse.count) : 0);
  }
  s.asset_extras = ToJson(model.asset.extras);
  return s;
}

Result<std::vector<Vec3f>> ReadGlbPositions(const std::filesystem::path& path) {
  ICEF_ASSIGN_OR_RETURN(tinygltf::Model model, LoadGlb(path));
  const tinygltf::Accessor& a = model.accessors.at(model.meshes[0].primitives[0].attributes.at("POSITION"));
  const tinygltf::BufferView& view = model.bufferViews.at(a.bufferView);
  if (a.count * sizeof(Vec3f) + a.byteOffset > view.byteLength)
    return Status::Error(path.string() + ": POSITION runs past its buffer view");
  std::vector<Vec3f> out(a.count);
  std::memcpy(out.data(), model.buffers.at(view.buffer).data.data() + view.byteOffset + a.byteOffset,
              a.count * sizeof(Vec3f));
  return out;
}

Result<std::vector<Vec3f>> ReadGlbTarget(const std::filesystem::path& path, int target) {
  ICEF_ASSIGN_OR_RETURN(tinygltf::Model model, LoadGlb(path));
  const tinygltf::Primitive& p = model.meshes[0].primitives[0];
  if (target < 0 || static_cast<size_t>(target) >= p.targets.size())
    return Status::Error(path.string() + ": no morph target " + std::to_string(target));
  const tinygltf::Accessor& a = model.accessors.at(p.targets[target].at("POSITION"));
  std::vector<Vec3f> out(a.count, Vec3f::Zero());
  if (!a.sparse.isSparse) return out;
  const auto view = [&](int index, int offset) {
    const tinygltf::BufferView& v = model.bufferViews.at(index);
    return model.buffers.at(v.buffer).data.data() + v.byteOffset + offset;
  };
  const unsigned char* indices = view(a.sparse.indices.bufferView, a.sparse.indices.byteOffset);
  const unsigned char* values = view(a.sparse.values.bufferView, a.sparse.values.byteOffset);
  for (int k = 0; k < a.sparse.count; ++k) {
    uint32_t v;
    std::memcpy(&v, indices + 4 * k, 4);
    if (v >= out.size()) return Status::Error(path.string() + ": a sparse index out of range");
    std::memcpy(out[v].data(), values + 12 * k, 12);
  }
  return out;
}

}  // namespace icef::mesh
