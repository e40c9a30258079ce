#include "icef/app/detector_calibration.h"

#include <cmath>
#include <iomanip>
#include <optional>

#include "icef/face/face_model.h"
#include "icef/landmarks/face_landmark_detector.h"
#include "icef/landmarks/face_mesh.h"
#include "icef/synth/ground_truth_renderer.h"
#include "icef/synth/head_model.h"
#include "icef/synth/identity.h"
#include "icef/synth/synthesize.h"
#include "icef/track/detector_landmarks.h"

namespace icef {

namespace {

constexpr double kYaws[] = {-35, -20, -8, 0, 8, 20, 35};
constexpr double kPitches[] = {-15, -6, 0, 6, 15};
constexpr int kWidth = 360, kHeight = 480;
constexpr double kDistance = 3.0;

}  // namespace

Result<DetectorCalibration> CalibrateDetector(const std::vector<uint64_t>& seeds, const Executor& executor,
                                              std::ostream* log, bool mesh) {
  ICEF_ASSIGN_OR_RETURN(const FaceLandmarkDetector detector, FaceLandmarkDetector::Load());
  std::optional<FaceMesh> face_mesh;
  if (mesh) {
    ICEF_ASSIGN_OR_RETURN(FaceMesh loaded, FaceMesh::Load());
    face_mesh = std::move(loaded);
  }
  Intrinsics k;
  k.width = kWidth;
  k.height = kHeight;
  k.fl_x = k.fl_y = 1.4 * kHeight;
  k.cx = 0.5 * kWidth;
  k.cy = 0.5 * kHeight;
  synth::RenderOptions ro;
  ro.background = Vec3f::Constant(0.5f);
  DetectorCalibration cal;
  // Per landmark, the offset at view v is W f_v (W: 3 x 4) and its point m + W f_v should project
  // onto the detection: Gauss-Newton on the pixel residuals, the projection linearised at the
  // current point (a few passes; the offsets are small). A ridge keeps the offsets small where the
  // views cannot tell (a shift along a view's own ray does not move its projection): 0.1 head units
  // of offset cost as much as 0.3 px (constant term) or 1 px (view terms) of residual per view.
  struct Observation {
    Camera camera;
    Vec2d uv;
    Vec3d model;
    std::array<float, 4> features;
  };
  std::array<std::vector<Observation>, 68> observations;
  const std::vector<float> neutral(face::kNumExpressions, 0.f);
  for (uint64_t seed : seeds) {
    synth::IdentityParams identity = synth::IdentityParams::FromSeed(seed);
    identity.style = face::ExpressionStyle::Generic();
    const synth::HeadModel head(identity);
    const std::array<Vec3f, 68>& model = head.face().NeutralLandmarks();
    int views = 0;
    for (double pitch : kPitches)
      for (double yaw : kYaws) {
        const Camera camera = synth::OrbitCamera(k, kDistance, yaw, pitch);
        const Image image = CompositeOver(synth::RenderGroundTruth(head, camera, neutral, executor, ro), ro.background);
        const Result<FaceDetection> d = face_mesh ? DetectFaceWithMesh(detector, *face_mesh, image)
                                                  : detector.DetectFace(image, /*averaged=*/true);  // as the tracker detects
        if (!d.ok() || d->num_faces != 1) continue;
        ++views;
        const std::array<float, 4> f = track::ViewFeatures(camera.Center().cast<float>());
        for (int i = 0; i < 68; ++i)
          observations[i].push_back({camera, d->landmarks[i].cast<double>(), model[i].cast<double>(), f});
      }
    if (views < 6)
      return Status::Error("detector calibration: seed " + std::to_string(seed) + ": dlib found the face in fewer than 6 views");
    ++cal.identities;
    cal.views += views;
    if (log) *log << "detector calibration: seed " << seed << ": " << views << " views with one face\n";
  }
  using Mat12 = Eigen::Matrix<double, 12, 12>;
  using Vec12 = Eigen::Matrix<double, 12, 1>;
  auto point = [](const Observation& o, const Vec12& w) {
    Vec3d x = o.model;
    for (int c = 0; c < 4; ++c) x += w.segment<3>(3 * c) * o.features[c];
    return x;
  };
  for (int i = 0; i < 68; ++i) {
    Vec12 w = Vec12::Zero();
    for (int pass = 0; pass < 4; ++pass) {
      const double n = static_cast<double>(observations[i].size());
      Mat12 lhs = Mat12::Zero();
      lhs.diagonal().head<3>().setConstant(10.0 * n);
      lhs.diagonal().tail<9>().setConstant(100.0 * n);
      Vec12 rhs = -lhs * w;
      for (const Observation& o : observations[i]) {
        const Vec3d x = point(o, w);
        const Vec2d r = o.camera.Project(x)->uv - o.uv;
        Eigen::Matrix<double, 2, 3> j;
        for (int a = 0; a < 3; ++a) {
          const double h = 1e-5;
          Vec3d xp = x, xm = x;
          xp[a] += h;
          xm[a] -= h;
          j.col(a) = (o.camera.Project(xp)->uv - o.camera.Project(xm)->uv) / (2 * h);
        }
        Eigen::Matrix<double, 2, 12> jw;
        for (int c = 0; c < 4; ++c) jw.block<2, 3>(0, 3 * c) = j * o.features[c];
        lhs += jw.transpose() * jw;
        rhs -= jw.transpose() * r;
      }
      w += lhs.ldlt().solve(rhs);
    }
    for (int c = 0; c < 4; ++c) cal.coefficients[i][c] = w.segment<3>(3 * c).cast<float>();
    double sum = 0;
    for (const Observation& o : observations[i]) sum += (o.camera.Project(point(o, w))->uv - o.uv).norm();
    cal.residual_px[i] = sum / std::max<size_t>(1, observations[i].size());
  }
  return cal;
}

void PrintDetectorTable(const DetectorCalibration& c, std::ostream& out) {
  out << "// " << c.identities << " identities, " << c.views << " views; per landmark the offset's coefficients of "
      << "ViewFeatures (head units), then the reprojection residual in pixels at " << kWidth << "x" << kHeight << "\n";
  out << std::fixed;
  for (int i = 0; i < 68; ++i) {
    out << "    {{";
    for (int f = 0; f < 4; ++f)
      out << std::setprecision(4) << (f ? ", " : "") << "Vec3f(" << c.coefficients[i][f].x() << "f, "
          << c.coefficients[i][f].y() << "f, " << c.coefficients[i][f].z() << "f)";
    out << "}},  // " << i << " (" << std::setprecision(1) << c.residual_px[i] << " px)\n";
  }
}

}  // namespace icef
