#include "icef/field/landmark_triangulation.h"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>

namespace icef {

Status TriangulationOptions::Validate() const {
  if (max_iterations < 0 || max_iterations > 1000)
    return Status::Error("triangulation.max_iterations must be in [0, 1000]");
  if (min_views < 2) return Status::Error("triangulation.min_views must be >= 2");
  return Status::Ok();
}

std::string TriangulationOptions::ToString() const {
  std::ostringstream os;
  os << "TriangulationOptions(refine=" << (refine ? "true" : "false") << ", max_iterations=" << max_iterations
     << ", min_views=" << min_views << ")";
  return os.str();
}

std::optional<Vec3d> TriangulateLinear(const std::vector<PointObservation>& observations) {
  const int v = int(observations.size());
  if (v < 2) return std::nullopt;
  // Normal equations of the 2v x 3 system, accumulated row by row (fixed-size Eigen only).
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Vec3d atb = Vec3d::Zero();
  auto add_row = [&](const Eigen::RowVector3d& row, double rhs) {
    ata += row.transpose() * row;
    atb += row.transpose() * rhs;
  };
  for (int i = 0; i < v; ++i) {
    const Camera& cam = *observations[i].camera;
    const Intrinsics& k = cam.intrinsics();
    const Mat4d cw = cam.cam_from_world();
    const Eigen::Matrix3d r = cw.block<3, 3>(0, 0);
    const Vec3d t = cw.block<3, 1>(0, 3);
    // q = r p + t; depth = -q_z. u = cx + fx q_x / depth, v = cy - fy q_y / depth, i.e.
    //   (u - cx)(-q_z) - fx q_x = 0  and  (v - cy)(-q_z) + fy q_y = 0, scaled by 1/f.
    const double du = (observations[i].uv.x() - k.cx) / k.fl_x;
    const double dv = (observations[i].uv.y() - k.cy) / k.fl_y;
    add_row(-du * r.row(2) - r.row(0), du * t.z() + t.x());
    add_row(-dv * r.row(2) + r.row(1), dv * t.z() - t.y());
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(ata);
  const Vec3d ev = eig.eigenvalues();                 // ascending
  if (!(ev(0) > 1e-10 * ev(2))) return std::nullopt;  // rank-deficient: depth unobservable
  const Vec3d p = eig.eigenvectors() * ((eig.eigenvectors().transpose() * atb).cwiseQuotient(ev));
  if (!p.allFinite()) return std::nullopt;
  return p;
}

std::optional<ReprojectionResidual> ReprojectionResidualAt(const PointObservation& observation,
                                                           const Vec3d& p) {
  const Camera& cam = *observation.camera;
  const Intrinsics& k = cam.intrinsics();
  const Mat4d cw = cam.cam_from_world();
  const Eigen::Matrix3d r = cw.block<3, 3>(0, 0);
  const Vec3d q = r * p + cw.block<3, 1>(0, 3);
  const double depth = -q.z();
  if (depth <= 1e-12) return std::nullopt;
  ReprojectionResidual out;
  out.residual = Vec2d(k.cx + k.fl_x * q.x() / depth, k.cy - k.fl_y * q.y() / depth) - observation.uv;
  Eigen::Matrix<double, 2, 3> d_uv_d_q;
  d_uv_d_q << k.fl_x / depth, 0, k.fl_x * q.x() / (depth * depth),  //
      0, -k.fl_y / depth, -k.fl_y * q.y() / (depth * depth);
  out.jacobian = d_uv_d_q * r;
  return out;
}

namespace {
double SquaredError(const std::vector<PointObservation>& observations, const Vec3d& p, bool* behind) {
  double e = 0;
  *behind = false;
  for (const PointObservation& o : observations) {
    const auto res = ReprojectionResidualAt(o, p);
    if (!res) {
      *behind = true;
      return 0;
    }
    e += res->residual.squaredNorm();
  }
  return e;
}
}  // namespace

Vec3d RefineReprojection(const std::vector<PointObservation>& observations, const Vec3d& initial,
                         int max_iterations) {
  Vec3d p = initial;
  bool behind = false;
  double error = SquaredError(observations, p, &behind);
  if (behind) return initial;
  for (int it = 0; it < max_iterations; ++it) {
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Vec3d jtr = Vec3d::Zero();
    for (const PointObservation& o : observations) {
      const auto res = ReprojectionResidualAt(o, p);
      jtj += res->jacobian.transpose() * res->jacobian;
      jtr += res->jacobian.transpose() * res->residual;
    }
    const Vec3d step = jtj.ldlt().solve(-jtr);
    if (!step.allFinite()) break;
    // Halve the step until the error does not grow (keeps Gauss-Newton monotone).
    double scale = 1.0;
    bool accepted = false;
    for (int tries = 0; tries < 8 && !accepted; ++tries, scale *= 0.5) {
      const Vec3d candidate = p + scale * step;
      const double e = SquaredError(observations, candidate, &behind);
      if (!behind && e <= error) {
        p = candidate;
        error = e;
        accepted = true;
      }
    }
    if (!accepted || step.norm() < 1e-12 * (1 + p.norm())) break;
  }
  return p;
}

double TriangulatedLandmarks::MeanRms() const {
  double s = 0;
  for (double r : rms_reprojection) s += r;
  return rms_reprojection.empty() ? 0 : s / double(rms_reprojection.size());
}

std::string TriangulatedLandmarks::ToString() const {
  std::ostringstream os;
  os << "TriangulatedLandmarks(points=" << points.size() << ", mean_rms_px=" << MeanRms() << ")";
  return os.str();
}

Result<TriangulatedLandmarks> TriangulateLandmarks(const std::vector<Frame>& frames,
                                                   const TriangulationOptions& options) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  TriangulatedLandmarks out;
  for (int l = 0; l < kNumLandmarks; ++l) {
    std::vector<PointObservation> obs;
    for (const Frame& f : frames) {
      if (!f.landmarks_2d || int(f.landmarks_2d->size()) != kNumLandmarks) continue;
      if (f.landmarks_2d_visible && int(f.landmarks_2d_visible->size()) == kNumLandmarks &&
          !(*f.landmarks_2d_visible)[l])
        continue;
      obs.push_back(PointObservation{&f.camera, (*f.landmarks_2d)[l].cast<double>()});
    }
    const std::string name = "landmark " + std::to_string(l);
    if (int(obs.size()) < options.min_views) {
      return Status::Error(name + ": visible in " + std::to_string(obs.size()) + " view(s), need at least " +
                           std::to_string(options.min_views) + " to triangulate");
    }
    std::optional<Vec3d> p = TriangulateLinear(obs);
    if (!p) return Status::Error(name + ": degenerate camera geometry, cannot triangulate");
    if (options.refine) p = RefineReprojection(obs, *p, options.max_iterations);
    double sq = 0;
    for (const PointObservation& o : obs) {
      const auto res = ReprojectionResidualAt(o, *p);
      if (!res) return Status::Error(name + ": triangulated behind a camera (inconsistent 2D landmarks?)");
      sq += res->residual.squaredNorm();
    }
    out.points.push_back(p->cast<float>());
    out.num_views.push_back(int(obs.size()));
    out.rms_reprojection.push_back(std::sqrt(sq / double(obs.size())));
  }
  return out;
}

}  // namespace icef
