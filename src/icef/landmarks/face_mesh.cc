#include "icef/landmarks/face_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "icef/infer/tfjs_graph.h"

namespace icef {

struct FaceMesh::Impl {
  infer::TfjsGraph graph;
};

std::string FaceMeshResult::ToString() const {
  std::ostringstream s;
  s << "FaceMeshResult(" << mesh.size() << " points, score " << face_score << ", crop " << roi_size
    << " px at (" << roi_center.x() << ", " << roi_center.y() << "), " << roi_angle << " rad)";
  return s.str();
}

const std::array<int, 68>& FaceMesh::Ibug68Index() {
  static const std::array<int, 68> index = {
      // jaw line, image left to right (the subject's right ear to left ear)
      127, 234, 93, 132, 58, 172, 150, 176, 152, 400, 379, 397, 288, 361, 323, 454, 356,
      // brows: the subject's right (image left), then left, each outer to inner / inner to outer
      70, 63, 105, 66, 107, 336, 296, 334, 293, 300,
      // nose bridge top to tip, then the nostrils' base left to right
      168, 197, 5, 4, 75, 97, 2, 326, 305,
      // eyes: outer corner, upper lid (2), inner corner, lower lid (2); the subject's right, then left
      33, 160, 158, 133, 153, 144, 362, 385, 387, 263, 373, 380,
      // outer lips from the left corner clockwise, then inner lips
      61, 39, 37, 0, 267, 269, 291, 405, 314, 17, 84, 181, 78, 82, 13, 312, 308, 317, 14, 87};
  return index;
}

Result<FaceMesh> FaceMesh::Load(const std::filesystem::path& dir) {
  ICEF_ASSIGN_OR_RETURN(
      infer::TfjsGraph graph,
      infer::LoadInstalledGraph(dir, "ICEF_FACEMESH_MODEL", kDefaultFaceMeshDir, "facemesh.json",
                                {kInputSize, kInputSize, 3}, "face-mesh model"));
  FaceMesh mesh;
  auto impl = std::make_shared<Impl>();
  impl->graph = std::move(graph);
  mesh.impl_ = std::move(impl);
  return mesh;
}

void FaceMeshRoi(const std::vector<Vec2f>& points, const Vec2f& eye_a, const Vec2f& eye_b, float scale,
                 Vec2f& center, float& size, float& angle) {
  const Vec2f eyes = eye_b - eye_a;
  angle = std::atan2(eyes.y(), eyes.x());
  const float c = std::cos(angle), s = std::sin(angle);
  // The bounding box in the turned frame (x along the eye line).
  float lo_u = 1e30f, hi_u = -1e30f, lo_v = 1e30f, hi_v = -1e30f;
  for (const Vec2f& p : points) {
    const float u = c * p.x() + s * p.y();
    const float v = -s * p.x() + c * p.y();
    lo_u = std::min(lo_u, u);
    hi_u = std::max(hi_u, u);
    lo_v = std::min(lo_v, v);
    hi_v = std::max(hi_v, v);
  }
  const float mu = 0.5f * (lo_u + hi_u), mv = 0.5f * (lo_v + hi_v);
  center = Vec2f(c * mu - s * mv, s * mu + c * mv);
  size = std::max(hi_u - lo_u, hi_v - lo_v) * scale;
}

namespace {

// Bilinear sample of channel ch at continuous image position (x, y) (pixel centres at +0.5),
// clamped to the border.
float Sample(const Image& image, float x, float y, int ch) {
  const float fx = std::clamp(x - 0.5f, 0.f, float(image.width - 1));
  const float fy = std::clamp(y - 0.5f, 0.f, float(image.height - 1));
  const int x0 = int(fx), y0 = int(fy);
  const int x1 = std::min(x0 + 1, image.width - 1), y1 = std::min(y0 + 1, image.height - 1);
  const float ax = fx - float(x0), ay = fy - float(y0);
  const int c = image.channels == 1 ? 0 : ch;
  return (1 - ay) * ((1 - ax) * image.At(x0, y0, c) + ax * image.At(x1, y0, c)) +
         ay * ((1 - ax) * image.At(x0, y1, c) + ax * image.At(x1, y1, c));
}

}  // namespace

Result<FaceMeshResult> FaceMesh::RunCrop(const Image& image, const Vec2f& center, float size,
                                         float angle) const {
  if (image.empty()) return Status::Error("face mesh: empty image");
  if (!(size > 1.f) || !std::isfinite(size) || !center.allFinite())
    return Status::Error("face mesh: bad crop (size " + std::to_string(size) + ")");
  const int n = kInputSize;
  const float c = std::cos(angle), s = std::sin(angle);
  const float step = size / float(n);
  // Average k x k bilinear samples per crop pixel when the crop shrinks the photo (no aliasing).
  const int k = std::clamp(int(std::ceil(step)), 1, 8);
  infer::Tensor3 crop(n, n, 3);
  for (int v = 0; v < n; ++v) {
    for (int u = 0; u < n; ++u) {
      for (int ch = 0; ch < 3; ++ch) {
        float sum = 0.f;
        for (int i = 0; i < k; ++i)
          for (int j = 0; j < k; ++j) {
            const float du = ((float(u) + (float(j) + 0.5f) / float(k)) / float(n) - 0.5f) * size;
            const float dv = ((float(v) + (float(i) + 0.5f) / float(k)) / float(n) - 0.5f) * size;
            sum += Sample(image, center.x() + c * du - s * dv, center.y() + s * du + c * dv, ch);
          }
        crop.At(v, u, ch) = sum / float(k * k);
      }
    }
  }
  ICEF_ASSIGN_OR_RETURN(auto out, impl_->graph.Run(crop, {"output_mesh", "output_faceflag"}));
  const infer::Tensor3& raw = out.at("output_mesh");
  if (raw.data.size() != size_t(3 * kPoints)) return Status::Error("face mesh: unexpected output size");
  FaceMeshResult result;
  result.face_score = out.at("output_faceflag").data.at(0);
  result.roi_center = center;
  result.roi_size = size;
  result.roi_angle = angle;
  result.mesh.resize(kPoints);
  for (int p = 0; p < kPoints; ++p) {
    const float du = (raw.data[3 * p] / float(n) - 0.5f) * size;
    const float dv = (raw.data[3 * p + 1] / float(n) - 0.5f) * size;
    result.mesh[p] =
        Vec3f(center.x() + c * du - s * dv, center.y() + s * du + c * dv, raw.data[3 * p + 2] * step);
  }
  result.landmarks.resize(68);
  for (int i = 0; i < 68; ++i) result.landmarks[i] = result.mesh[Ibug68Index()[i]].head<2>();
  return result;
}

Result<FaceMeshResult> FaceMesh::Run(const Image& image, const std::vector<Vec2f>& landmarks) const {
  if (landmarks.size() != 68)
    return Status::Error("face mesh: expected 68 landmarks, got " + std::to_string(landmarks.size()));
  // First pass: dlib's 68 points span brows to chin; the mesh also covers the forehead, so the
  // crop is taken a little larger and higher than MediaPipe's mesh-based one.
  auto mean = [&](int a, int b) {
    Vec2f m = Vec2f::Zero();
    for (int i = a; i < b; ++i) m += landmarks[i];
    return Vec2f(m / float(b - a));
  };
  Vec2f center;
  float size = 0.f, angle = 0.f;
  FaceMeshRoi(landmarks, mean(36, 42), mean(42, 48), kRoiScale * 1.15f, center, size, angle);
  center += Vec2f(std::sin(angle), -std::cos(angle)) * (0.06f * size);
  ICEF_ASSIGN_OR_RETURN(FaceMeshResult first, RunCrop(image, center, size, angle));
  // Second pass: MediaPipe's own crop around the first mesh.
  std::vector<Vec2f> points(kPoints);
  for (int p = 0; p < kPoints; ++p) points[p] = first.mesh[p].head<2>();
  FaceMeshRoi(points, points[33], points[263], kRoiScale, center, size, angle);
  return RunCrop(image, center, size, angle);
}

Result<FaceDetection> DetectFaceWithMesh(const FaceLandmarkDetector& detector, const FaceMesh& mesh,
                                         const Image& image) {
  ICEF_ASSIGN_OR_RETURN(FaceDetection face, detector.DetectFace(image, /*averaged=*/true));
  const Image rgb = image.HasAlpha() ? CompositeOver(image, Vec3f::Ones()) : image;
  ICEF_ASSIGN_OR_RETURN(const FaceMeshResult result, mesh.Run(rgb, face.landmarks));
  if (!(result.face_score >= FaceMesh::kMinFaceScore))
    return Status::Error("no face found (the face mesh's face score is " + std::to_string(result.face_score) +
                         ")");
  face.landmarks = result.landmarks;
  return face;
}

}  // namespace icef
