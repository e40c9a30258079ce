#include "icef/model/model_setup.h"

#include "icef/field/region_mask.h"

namespace icef {

Result<ModelSetup> ModelSetup::FromDataset(const Dataset& dataset, const Executor& executor) {
  if (dataset.train.empty())
    return Status::Error(dataset.root.string() + ": the dataset has no training frames");
  ModelSetup s;
  s.aabb = dataset.aabb;
  s.expression_dim = dataset.expression_dim;
  s.expression_names = dataset.expression_names;
  for (const Frame& f : dataset.train) {
    s.training_expressions.push_back(f.expression);
    s.training_cameras.push_back(f.camera);
  }
  s.background = dataset.background;
  ICEF_ASSIGN_OR_RETURN(const RegionMask mask,
                        RegionMask::FromDataset(dataset, RegionMaskOptions{}, executor));
  s.mask_landmarks = mask.landmarks();
  s.mask_source = mask.source();
  return s;
}

namespace {

Json SimilarityToJson(const face::Similarity& sim) {
  Json rot = Json::array();
  for (int r = 0; r < 3; ++r) rot.push_back({sim.rotation(r, 0), sim.rotation(r, 1), sim.rotation(r, 2)});
  return {{"scale", sim.scale},
          {"rotation", rot},
          {"translation", {sim.translation.x(), sim.translation.y(), sim.translation.z()}}};
}

Result<face::Similarity> SimilarityFromJson(const JsonObjectView& parent, const char* key) {
  ICEF_ASSIGN_OR_RETURN(const JsonObjectView sim, parent.Object(key));
  face::Similarity s;
  ICEF_ASSIGN_OR_RETURN(s.scale, sim.Number("scale"));
  if (!(s.scale > 0)) return sim.Error("scale", "must be > 0");
  ICEF_ASSIGN_OR_RETURN(const auto rot, sim.NumberMatrix("rotation", 3, 3));
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) s.rotation(r, c) = rot[r][c];
  const Mat3d& rm = s.rotation;
  if ((rm * rm.transpose() - Mat3d::Identity()).norm() > 1e-4 || rm.determinant() < 0)
    return sim.Error("rotation", "must be a rotation matrix");
  ICEF_ASSIGN_OR_RETURN(const auto t, sim.NumberArray("translation", 3));
  s.translation = Vec3d(t[0], t[1], t[2]);
  return s;
}

}  // namespace

Json ModelSetup::ToJson() const {
  Json j;
  j["aabb"] = {{aabb.min.x(), aabb.min.y(), aabb.min.z()}, {aabb.max.x(), aabb.max.y(), aabb.max.z()}};
  j["expression_dim"] = expression_dim;
  j["expression_names"] = expression_names;
  j["training_expressions"] = training_expressions;
  Json lm = Json::array();
  for (const Vec3f& p : mask_landmarks) lm.push_back({p.x(), p.y(), p.z()});
  j["mask_landmarks"] = lm;
  j["mask_source"] = mask_source;
  j["background"] = {background.x(), background.y(), background.z()};
  Json cams = Json::array();
  for (const Camera& c : training_cameras) {
    const Intrinsics& k = c.intrinsics();
    Json m = Json::array();
    for (int r = 0; r < 4; ++r)
      m.push_back({c.world_from_cam()(r, 0), c.world_from_cam()(r, 1), c.world_from_cam()(r, 2),
                   c.world_from_cam()(r, 3)});
    cams.push_back({{"w", k.width},
                    {"h", k.height},
                    {"fl_x", k.fl_x},
                    {"fl_y", k.fl_y},
                    {"cx", k.cx},
                    {"cy", k.cy},
                    {"transform_matrix", m}});
  }
  j["training_cameras"] = cams;
  if (prior_light) j["prior_light"] = {prior_light->x(), prior_light->y(), prior_light->z()};
  if (face_fit) {
    const face::FaceFit& f = *face_fit;
    Json shape = Json::object();
    const auto values = f.shape.ToArray();
    for (int i = 0; i < face::ShapeParams::kCount; ++i) shape[face::kShapeParamNames[i]] = values[i];
    Json style = Json::object();
    for (const auto& [name, value] : f.style.Fields()) style[name] = value;
    j["face_fit"] = {{"shape", shape},
                     {"style", style},
                     {"head_from_world", SimilarityToJson(f.head_from_world)},
                     {"rms_iod", f.rms_iod},
                     {"max_iod", f.max_iod},
                     {"landmarks_used", f.landmarks_used},
                     {"landmarks_total", f.landmarks_total},
                     {"iterations", f.iterations}};
  }
  if (ict_fit) {
    j["ict_fit"] = {{"identity", ict_fit->identity},
                    {"head_from_world", SimilarityToJson(ict_fit->head_from_world)},
                    {"rms_iod", ict_fit->rms_iod}};
  }
  return j;
}

Result<ModelSetup> ModelSetup::FromJson(const Json& json, const std::string& origin) {
  ICEF_ASSIGN_OR_RETURN(const JsonObjectView v, JsonObjectView::Make(json, origin, "setup"));
  ModelSetup s;
  ICEF_ASSIGN_OR_RETURN(const auto aabb, v.NumberMatrix("aabb", 2, 3));
  s.aabb.min = Vec3f(aabb[0][0], aabb[0][1], aabb[0][2]);
  s.aabb.max = Vec3f(aabb[1][0], aabb[1][1], aabb[1][2]);
  if (!s.aabb.IsValid()) return v.Error("aabb", "min must be below max");
  ICEF_ASSIGN_OR_RETURN(s.expression_dim, v.Int("expression_dim"));
  if (s.expression_dim < 1) return v.Error("expression_dim", "must be >= 1");
  ICEF_ASSIGN_OR_RETURN(s.expression_names, v.StringArray("expression_names"));
  ICEF_ASSIGN_OR_RETURN(const auto expressions, v.NumberMatrix("training_expressions", -1, s.expression_dim));
  for (const auto& row : expressions) s.training_expressions.emplace_back(row.begin(), row.end());
  if (s.training_expressions.empty()) return v.Error("training_expressions", "must not be empty");
  ICEF_ASSIGN_OR_RETURN(const auto lm, v.NumberMatrix("mask_landmarks", kNumLandmarks, 3));
  for (const auto& p : lm) s.mask_landmarks.emplace_back(p[0], p[1], p[2]);
  ICEF_ASSIGN_OR_RETURN(s.mask_source, v.String("mask_source"));
  ICEF_ASSIGN_OR_RETURN(const auto bg, v.NumberArray("background", 3));
  s.background = Vec3f(bg[0], bg[1], bg[2]);
  ICEF_ASSIGN_OR_RETURN(const std::vector<JsonObjectView> cams, v.ObjectArray("training_cameras"));
  for (const JsonObjectView& c : cams) {
    Intrinsics k;
    ICEF_ASSIGN_OR_RETURN(k.width, c.Int("w"));
    ICEF_ASSIGN_OR_RETURN(k.height, c.Int("h"));
    ICEF_ASSIGN_OR_RETURN(k.fl_x, c.Number("fl_x"));
    ICEF_ASSIGN_OR_RETURN(k.fl_y, c.Number("fl_y"));
    ICEF_ASSIGN_OR_RETURN(k.cx, c.Number("cx"));
    ICEF_ASSIGN_OR_RETURN(k.cy, c.Number("cy"));
    ICEF_RETURN_IF_ERROR(k.Validate().WithContext(origin + ": training_cameras"));
    ICEF_ASSIGN_OR_RETURN(const auto m, c.NumberMatrix("transform_matrix", 4, 4));
    Mat4d pose;
    for (int r = 0; r < 4; ++r)
      for (int col = 0; col < 4; ++col) pose(r, col) = m[r][col];
    ICEF_RETURN_IF_ERROR(ValidateRigid(pose).WithContext(origin + ": training_cameras transform_matrix"));
    s.training_cameras.emplace_back(k, pose);
  }
  if (s.training_cameras.size() != s.training_expressions.size())
    return v.Error("training_cameras", "expected one camera per training expression");
  if (v.Has("face_fit")) {
    ICEF_ASSIGN_OR_RETURN(const JsonObjectView fv, v.Object("face_fit"));
    face::FaceFit f;
    ICEF_ASSIGN_OR_RETURN(const JsonObjectView shape, fv.Object("shape"));
    std::array<float, face::ShapeParams::kCount> values;
    for (int i = 0; i < face::ShapeParams::kCount; ++i) {
      ICEF_ASSIGN_OR_RETURN(const double x, shape.Number(face::kShapeParamNames[i]));
      if (!(x > 0)) return shape.Error(face::kShapeParamNames[i], "must be > 0");
      values[i] = static_cast<float>(x);
    }
    f.shape = face::ShapeParams::FromArray(values);
    if (fv.Has("style")) {  // setups saved before styles were fitted have none: the generic style
      ICEF_ASSIGN_OR_RETURN(const JsonObjectView style, fv.Object("style"));
      for (const auto& [name, generic] : face::ExpressionStyle::Generic().Fields()) {
        ICEF_ASSIGN_OR_RETURN(const double x, style.Number(name));
        f.style.SetField(name, static_cast<float>(x));
      }
      if (Status st = f.style.Validate(); !st.ok()) return fv.Error("style", st.message());
    }
    ICEF_ASSIGN_OR_RETURN(f.head_from_world, SimilarityFromJson(fv, "head_from_world"));
    ICEF_ASSIGN_OR_RETURN(f.rms_iod, fv.Number("rms_iod"));
    ICEF_ASSIGN_OR_RETURN(f.max_iod, fv.Number("max_iod"));
    ICEF_ASSIGN_OR_RETURN(f.landmarks_used, fv.Int("landmarks_used"));
    ICEF_ASSIGN_OR_RETURN(f.landmarks_total, fv.Int("landmarks_total"));
    ICEF_ASSIGN_OR_RETURN(f.iterations, fv.Int("iterations"));
    s.face_fit = f;
  }
  if (v.Has("ict_fit")) {
    ICEF_ASSIGN_OR_RETURN(const JsonObjectView fv, v.Object("ict_fit"));
    IctFaceFit f;
    ICEF_ASSIGN_OR_RETURN(const std::vector<double> identity, fv.NumberArray("identity"));
    for (const double c : identity) {
      if (!std::isfinite(c)) return fv.Error("identity", "must be finite numbers");
      f.identity.push_back(static_cast<float>(c));
    }
    ICEF_ASSIGN_OR_RETURN(f.head_from_world, SimilarityFromJson(fv, "head_from_world"));
    ICEF_ASSIGN_OR_RETURN(f.rms_iod, fv.Number("rms_iod"));
    s.ict_fit = std::move(f);
  }
  if (v.Has("prior_light")) {
    ICEF_ASSIGN_OR_RETURN(const auto l, v.NumberArray("prior_light", 3));
    for (double x : l)
      if (!std::isfinite(x)) return v.Error("prior_light", "must be 3 finite numbers");
    s.prior_light = Vec3f(float(l[0]), float(l[1]), float(l[2]));
  }
  return s;
}

int ModelSetup::ExpressionIndex(const std::string& name) const {
  for (size_t i = 0; i < expression_names.size(); ++i)
    if (expression_names[i] == name) return static_cast<int>(i);
  return -1;
}

}  // namespace icef
