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

// One landmark detected in one view: the camera, the detection (pixels), the face model's own
// landmark (canonical head frame) and the view's features (track::ViewFeatures).
struct Observation {
  Camera camera;
  Vec2d uv;
  Vec3d model;
  std::array<float, 4> features;
};
using Observations = std::array<std::vector<Observation>, 68>;

// The detector the calibration runs: dlib's (averaged, as the tracker detects), or the face mesh's.
struct CalibrationDetector {
  FaceLandmarkDetector dlib;
  std::optional<FaceMesh> mesh;

  Result<FaceDetection> Detect(const Image& image) const {
    return mesh ? DetectFaceWithMesh(dlib, *mesh, image) : dlib.DetectFace(image, /*averaged=*/true);
  }
};

Intrinsics CalibrationIntrinsics() {
  Intrinsics k;
  k.width = kWidth;
  k.height = kHeight;
  k.fl_x = k.fl_y = 1.4 * kHeight;
  k.cx = 0.5 * kWidth;
  k.cy = 0.5 * kHeight;
  return k;
}

// Renders identity `seed` (generic style, neutral) from the grid of views and adds the views with
// exactly one detected face to `observations`; returns how many there were.
int ObserveIdentity(uint64_t seed, const CalibrationDetector& detector, const Executor& executor,
                    Observations* observations) {
  synth::RenderOptions ro;
  ro.background = Vec3f::Constant(0.5f);
  const Intrinsics k = CalibrationIntrinsics();
  const std::vector<float> neutral(face::kNumExpressions, 0.f);
  synth::IdentityParams identity = synth::IdentityParams::FromSeed(seed);
  identity.style = face::ExpressionStyle::Generic();
  const synth::HeadModel head(identity);
  const std::array<Vec3f, 68>& model = head.face().NeutralLandmarks();
  int views = 0;
  for (double pitch : kPitches)
    for (double yaw : kYaws) {
      const Camera camera = synth::OrbitCamera(k, kDistance, yaw, pitch);
      const Image image =
          CompositeOver(synth::RenderGroundTruth(head, camera, neutral, executor, ro), ro.background);
      const Result<FaceDetection> d = detector.Detect(image);
      if (!d.ok() || d->num_faces != 1) continue;
      ++views;
      const std::array<float, 4> f = track::ViewFeatures(camera.Center().cast<float>());
      for (int i = 0; i < 68; ++i)
        (*observations)[i].push_back({camera, d->landmarks[i].cast<double>(), model[i].cast<double>(), f});
    }
  return views;
}

using Mat12 = Eigen::Matrix<double, 12, 12>;
using Vec12 = Eigen::Matrix<double, 12, 1>;

// The observation's point with offset coefficients w (W: 3 x 4, column-major in w).
Vec3d OffsetPoint(const Observation& o, const Vec12& w) {
  Vec3d x = o.model;
  for (int c = 0; c < 4; ++c) x += w.segment<3>(3 * c) * o.features[c];
  return x;
}

// One landmark's offset coefficients W (the offset at view v is W f_v) such that m + W f_v projects
// onto the detections: Gauss-Newton on the pixel residuals, the projection linearised at the
// current point (a few passes; the offsets are small). A ridge keeps the offsets small where the
// views cannot tell (a shift along a view's own ray does not move its projection): 0.1 head units
// of offset cost as much as 0.3 px (constant term) or 1 px (view terms) of residual per view.
Vec12 FitLandmarkOffset(const std::vector<Observation>& observations) {
  Vec12 w = Vec12::Zero();
  for (int pass = 0; pass < 4; ++pass) {
    const double n = static_cast<double>(observations.size());
    Mat12 lhs = Mat12::Zero();
    lhs.diagonal().head<3>().setConstant(10.0 * n);
    lhs.diagonal().tail<9>().setConstant(100.0 * n);
    Vec12 rhs = -lhs * w;
    for (const Observation& o : observations) {
      const Vec3d x = OffsetPoint(o, w);
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
  return w;
}

}  // namespace

Result<DetectorCalibration> CalibrateDetector(const std::vector<uint64_t>& seeds, const Executor& executor,
                                              std::ostream* log, bool mesh) {
  ICEF_ASSIGN_OR_RETURN(FaceLandmarkDetector dlib, FaceLandmarkDetector::Load());
  CalibrationDetector detector{std::move(dlib), std::nullopt};
  if (mesh) {
    ICEF_ASSIGN_OR_RETURN(FaceMesh loaded, FaceMesh::Load());
    detector.mesh = std::move(loaded);
  }
  DetectorCalibration cal;
  Observations observations;
  for (uint64_t seed : seeds) {
    const int views = ObserveIdentity(seed, detector, executor, &observations);
    if (views < 6)
      return Status::Error("detector calibration: seed " + std::to_string(seed) +
                           ": dlib found the face in fewer than 6 views");
    ++cal.identities;
    cal.views += views;
    if (log) *log << "detector calibration: seed " << seed << ": " << views << " views with one face\n";
  }
  for (int i = 0; i < 68; ++i) {
    const Vec12 w = FitLandmarkOffset(observations[i]);
    for (int c = 0; c < 4; ++c) cal.coefficients[i][c] = w.segment<3>(3 * c).cast<float>();
    double sum = 0;
    for (const Observation& o : observations[i])
      sum += (o.camera.Project(OffsetPoint(o, w))->uv - o.uv).norm();
    cal.residual_px[i] = sum / std::max<size_t>(1, observations[i].size());
  }
  return cal;
}

void PrintDetectorTable(const DetectorCalibration& c, std::ostream& out) {
  out << "// " << c.identities << " identities, " << c.views
      << " views; per landmark the offset's coefficients of "
      << "ViewFeatures (head units), then the reprojection residual in pixels at " << kWidth << "x" << kHeight
      << "\n";
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
