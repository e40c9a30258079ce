// SaveDataset: writes transforms_{train,test,val}.json in the format LoadDataset reads.
#include "icef/data/dataset.h"
#include "icef/io/atomic_file.h"
#include "icef/io/json_util.h"

namespace icef {

namespace fs = std::filesystem;

namespace {

bool SameIntrinsics(const Intrinsics& a, const Intrinsics& b) {
  return a.width == b.width && a.height == b.height && a.fl_x == b.fl_x && a.fl_y == b.fl_y && a.cx == b.cx &&
         a.cy == b.cy;
}

void PutIntrinsics(const Intrinsics& k, Json& out) {
  out["w"] = k.width;
  out["h"] = k.height;
  out["fl_x"] = k.fl_x;
  out["fl_y"] = k.fl_y;
  out["cx"] = k.cx;
  out["cy"] = k.cy;
}

Json FloatArray(const float* values, int n) {
  Json a = Json::array();
  for (int i = 0; i < n; ++i) a.push_back(JsonFloat(values[i]));
  return a;
}

// [[x, y(, z)] ...] of 2D or 3D points.
template <typename Point>
Json PointArray(const std::vector<Point>& points) {
  Json l = Json::array();
  for (const Point& p : points) l.push_back(FloatArray(p.data(), static_cast<int>(p.size())));
  return l;
}

// Checks what the loader would reject, so that a saved dataset always loads back.
Status CheckFrame(const Dataset& d, const Frame& f, const std::string& where) {
  if (f.file_path.empty()) return Status::Error(where + ".file_path: empty");
  if (f.expression.size() != size_t(d.expression_dim))
    return Status::Error(where + ".expression: has " + std::to_string(f.expression.size()) +
                         " values, expression_dim is " + std::to_string(d.expression_dim));
  if (f.landmarks_2d && f.landmarks_2d->size() != size_t(kNumLandmarks))
    return Status::Error(where + ".landmarks_2d: expected 68 points");
  if (f.landmarks_2d_visible && (!f.landmarks_2d || f.landmarks_2d_visible->size() != size_t(kNumLandmarks)))
    return Status::Error(where + ".landmarks_2d_visible: expected 68 flags alongside landmarks_2d");
  if (f.landmarks_3d && f.landmarks_3d->size() != size_t(kNumLandmarks))
    return Status::Error(where + ".landmarks_3d: expected 68 points");
  if (f.neutral_landmarks_2d && f.neutral_landmarks_2d->size() != size_t(kNumLandmarks))
    return Status::Error(where + ".neutral_landmarks_2d: expected 68 points");
  if (f.neutral_landmarks_3d && f.neutral_landmarks_3d->size() != size_t(kNumLandmarks))
    return Status::Error(where + ".neutral_landmarks_3d: expected 68 points");
  if (Status s = ValidateRigid(f.camera.world_from_cam()); !s.ok())
    return Status::Error(where + ".transform_matrix: " + s.message());
  if (Status s = f.camera.intrinsics().Validate(); !s.ok())
    return Status::Error(where + ": intrinsics: " + s.message());
  return Status::Ok();
}

Json FrameToJson(const Frame& f, const std::optional<Intrinsics>& global) {
  Json j = Json::object();
  j["file_path"] = f.file_path;
  Json m = Json::array();
  for (int r = 0; r < 4; ++r) {
    Json row = Json::array();
    for (int c = 0; c < 4; ++c) row.push_back(f.camera.world_from_cam()(r, c));
    m.push_back(row);
  }
  j["transform_matrix"] = m;
  if (!global || !SameIntrinsics(*global, f.camera.intrinsics())) PutIntrinsics(f.camera.intrinsics(), j);
  if (!f.expression.empty()) j["expression"] = FloatArray(f.expression.data(), int(f.expression.size()));
  if (f.landmarks_2d) j["landmarks_2d"] = PointArray(*f.landmarks_2d);
  if (f.landmarks_2d_visible) {
    Json v = Json::array();
    for (bool b : *f.landmarks_2d_visible) v.push_back(b);
    j["landmarks_2d_visible"] = v;
  }
  if (f.landmarks_3d) j["landmarks_3d"] = PointArray(*f.landmarks_3d);
  if (f.delta) j["delta"] = *f.delta;
  if (f.tier) j["tier"] = TierName(*f.tier);
  if (f.neutral_file_path) j["neutral_file_path"] = *f.neutral_file_path;
  if (f.neutral_landmarks_2d) j["neutral_landmarks_2d"] = PointArray(*f.neutral_landmarks_2d);
  if (f.neutral_landmarks_3d) j["neutral_landmarks_3d"] = PointArray(*f.neutral_landmarks_3d);
  if (f.bbox) j["bbox"] = FloatArray(f.bbox->data(), 4);
  return j;
}

}  // namespace

Status SaveDataset(const Dataset& d) {
  std::error_code ec;
  if (!fs::is_directory(d.root, ec))
    return Status::Error(d.root.string() + ": dataset directory does not exist");
  if (d.expression_dim < 0) return Status::Error(d.root.string() + ": expression_dim must be >= 0");
  if (!d.expression_names.empty() && d.expression_names.size() != size_t(d.expression_dim))
    return Status::Error(d.root.string() + ": expression_names: has " +
                         std::to_string(d.expression_names.size()) + " names, expression_dim is " +
                         std::to_string(d.expression_dim));
  if (!d.aabb.IsValid()) return Status::Error(d.root.string() + ": aabb: min must be below max");

  const std::pair<const char*, const std::vector<Frame>*> splits[] = {
      {"train", &d.train}, {"test", &d.test}, {"val", &d.val}};
  // Global intrinsics: those of the first frame; frames that differ carry their own.
  std::optional<Intrinsics> global;
  for (const auto& [name, frames] : splits) {
    for (size_t i = 0; i < frames->size(); ++i)
      ICEF_RETURN_IF_ERROR(
          CheckFrame(d, (*frames)[i], d.root.string() + ": " + name + "[" + std::to_string(i) + "]"));
    if (!global && !frames->empty()) global = frames->front().camera.intrinsics();
  }

  for (const auto& [name, frames] : splits) {
    if (std::string(name) == "val" && frames->empty()) continue;
    Json doc = Json::object();
    if (global) PutIntrinsics(*global, doc);
    doc["aabb"] = Json::array({FloatArray(d.aabb.min.data(), 3), FloatArray(d.aabb.max.data(), 3)});
    doc["expression_dim"] = d.expression_dim;
    if (!d.expression_names.empty()) doc["expression_names"] = d.expression_names;
    doc["background"] = FloatArray(d.background.data(), 3);
    if (d.background_file_path) doc["background_file_path"] = *d.background_file_path;
    if (d.tier_thresholds)
      doc["tier_thresholds"] = Json::array({(*d.tier_thresholds)[0], (*d.tier_thresholds)[1]});
    Json list = Json::array();
    for (const Frame& f : *frames) list.push_back(FrameToJson(f, global));
    doc["frames"] = std::move(list);
    ICEF_RETURN_IF_ERROR(
        WriteFileAtomic(d.root / ("transforms_" + std::string(name) + ".json"), FormatJson(doc)));
  }
  return Status::Ok();
}

}  // namespace icef
