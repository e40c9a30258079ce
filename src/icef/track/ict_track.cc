#include "icef/track/ict_track.h"

#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>

namespace icef::track {

namespace {

Vec3f ToWorld(const Vec3f& x_ict) { return (WorldFromIctHead().Apply(x_ict.cast<double>())).cast<float>(); }

}  // namespace

face::Similarity WorldFromIctHead() {
  face::Similarity s;
  s.scale = kWorldPerCm;
  s.translation = Vec3d(0, -0.052, 0.012);
  return s;
}

Result<TrackFit> FitIctTrack(const face::IctModel& model, std::span<const TrackFrame> frames,
                             const face::IctFitOptions& options) {
  std::vector<face::IctObservation> observations;
  for (const TrackFrame& f : frames) {
    observations.push_back(face::IctObservation{f.intrinsics, f.landmarks_2d, {}, std::nullopt});
    if (f.world_from_cam) observations.back().cam_from_world = f.world_from_cam->inverse();
  }
  ICEF_ASSIGN_OR_RETURN(const face::IctFit fit, face::FitIctToLandmarks(model, observations, options));
  // The head in the world: the known cameras' world with the fitted head_from_world, else the
  // fixed WorldFromIctHead with each camera placed around it.
  const face::Similarity world = WorldFromIctHead();
  const auto to_world = [&](const Vec3f& head) {
    return fit.head_from_world ? fit.head_from_world->ApplyInverse(head.cast<double>()).cast<float>()
                               : ToWorld(head);
  };
  TrackFit out;
  out.ict_identity = fit.identity;
  out.rms_iod = fit.rms_iod;
  out.max_iod = fit.max_iod;
  out.iterations = fit.iterations;
  out.head_from_world = fit.head_from_world;
  for (size_t k = 0; k < fit.photos.size(); ++k) {
    const face::IctPhotoFit& p = fit.photos[k];
    TrackedFrame f;
    if (frames[k].world_from_cam) {
      f.cam_from_head = *observations[k].cam_from_world;
    } else {
      // cam_from_ict = [R | T] (cm); the camera centre in the world: scale * (-R^T T) + t.
      const Mat3d r = p.cam_from_head.block<3, 3>(0, 0);
      const Vec3d centre_ict = -r.transpose() * p.cam_from_head.block<3, 1>(0, 3);
      const Vec3d centre = world.Apply(centre_ict);
      f.cam_from_head.block<3, 3>(0, 0) = r;
      f.cam_from_head.block<3, 1>(0, 3) = -r * centre;
    }
    f.expression = p.expression;
    const std::vector<Vec3f> landmarks = model.Landmarks(model.Mesh(fit.identity, p.expression));
    for (int i = 0; i < face::IctModel::kNumLandmarks; ++i) f.landmarks_head[i] = to_world(landmarks[i]);
    f.projected = p.projected;
    f.rms_iod = p.rms_iod;
    f.max_iod = p.max_iod;
    f.landmarks_used = p.landmarks_used;
    out.frames.push_back(std::move(f));
  }
  return out;
}

void AddIctReportFields(const TrackFit& fit, Json* report) {
  Json identity = Json::array();
  for (const float c : fit.ict_identity) identity.push_back(JsonFloat(c));
  (*report)["face_model"] = "ict";
  (*report)["ict_identity"] = identity;
}

std::vector<std::array<uint32_t, 3>> IctOuterTriangles(const face::IctModel& model) {
  const int face = model.PartIndex("face"), head = model.PartIndex("head_neck");
  std::vector<std::array<uint32_t, 3>> out;
  for (const auto& t : model.triangles()) {
    const int part = model.part_labels()[t[0]];
    if (part == face || part == head) out.push_back(t);
  }
  return out;
}

Image IctSilhouette(const face::IctModel& model, std::span<const float> identity,
                    std::span<const float> expression, const Camera& camera) {
  const std::vector<Vec3f> mesh = model.Mesh(identity, expression);
  constexpr int kShift = 4;  // fixed-point bits of the polygon corners
  constexpr double kOne = 1 << kShift;
  std::vector<std::optional<cv::Point>> projected(mesh.size());
  for (size_t v = 0; v < mesh.size(); ++v)
    if (const auto p = camera.Project(ToWorld(mesh[v]).cast<double>()))
      projected[v] = cv::Point(static_cast<int>(std::lround((p->uv.x() - 0.5) * kOne)),
                               static_cast<int>(std::lround((p->uv.y() - 0.5) * kOne)));
  cv::Mat mask = cv::Mat::zeros(camera.height(), camera.width(), CV_8U);
  for (const auto& t : IctOuterTriangles(model)) {
    if (!projected[t[0]] || !projected[t[1]] || !projected[t[2]]) continue;
    const cv::Point corners[3] = {*projected[t[0]], *projected[t[1]], *projected[t[2]]};
    cv::fillConvexPoly(mask, corners, 3, cv::Scalar(255), cv::LINE_8, kShift);
  }
  Image out(camera.width(), camera.height(), 1);
  for (int y = 0; y < camera.height(); ++y)
    for (int x = 0; x < camera.width(); ++x) out.At(x, y, 0) = mask.at<uint8_t>(y, x) ? 1.f : 0.f;
  return out;
}

Aabb IctHeadBounds(const face::IctModel& model, std::span<const float> identity, float margin) {
  const std::vector<float> neutral(model.num_expressions(), 0.f);
  Aabb box;
  box.min = Vec3f::Constant(std::numeric_limits<float>::infinity());
  box.max = -box.min;
  for (const Vec3f& v : model.Mesh(identity, neutral)) {
    const Vec3f w = ToWorld(v);
    box.min = box.min.cwiseMin(w);
    box.max = box.max.cwiseMax(w);
  }
  box.min -= Vec3f::Constant(margin);
  box.max += Vec3f::Constant(margin);
  return box;
}

}  // namespace icef::track
