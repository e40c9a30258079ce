#include "icef/track/track_fit.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "icef/face/expression.h"
#include "icef/face/face_model.h"
#include "icef/track/detector_landmarks.h"
#include "icef/track/track_fit_internal.h"

namespace icef::track {

namespace internal {

// Frames solved jointly with the shape at most; the others get their own pose and expression on
// the shape found (a long video would make the joint problem slow for nothing).
constexpr int kMaxJointFrames = 24;

Vec2d EyeCentre2d(const std::vector<Vec2f>& lm, int first) {
  Vec2d c = Vec2d::Zero();
  for (int i = first; i < first + 6; ++i) c += lm[i].cast<double>();
  return c / 6.0;
}
double Iod2d(const std::vector<Vec2f>& lm) { return (EyeCentre2d(lm, 36) - EyeCentre2d(lm, 42)).norm(); }

Mat3d AngleAxisMatrix(const double* aa) {
  double r[9];
  ceres::AngleAxisToRotationMatrix(aa, r);  // column major
  Mat3d m;
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) m(row, c) = r[3 * c + row];
  return m;
}

std::vector<float> ClampedExpression(const double* e, double max_expression) {
  std::vector<float> beta(kExpr);
  for (int i = 0; i < kExpr; ++i) beta[i] = static_cast<float>(std::clamp(e[i], 0.0, max_expression));
  return beta;
}

// The camera seeing the head frame (photos) or the dataset world (known cameras) for a pose.
Camera FrameCamera(const FrameProblem& fp, const Shared& shared, const double* pose) {
  if (shared.known_cameras) return Camera(fp.frame->intrinsics, *fp.frame->world_from_cam);
  Mat4d cam_from_head = Mat4d::Identity();
  cam_from_head.block<3, 3>(0, 0) = AngleAxisMatrix(pose) * fp.base_rotation;
  cam_from_head.block<3, 1>(0, 3) = Vec3d(pose[3], pose[4], pose[5]);
  return Camera(fp.frame->intrinsics, cam_from_head.inverse());
}

face::Similarity SharedSimilarity(const Shared& shared, const double* pose) {
  face::Similarity s;
  s.rotation = AngleAxisMatrix(pose) * shared.base.rotation;
  s.translation = Vec3d(pose[3], pose[4], pose[5]);
  s.scale = shared.base.scale * std::exp(pose[6]);
  return s;
}

// Projected model landmarks of a frame; nullopt entries are behind the camera.
std::vector<std::optional<Vec2d>> Project(const FrameProblem& fp, Shared& shared, const double* shape,
                                          const double* expression, const double* pose,
                                          std::array<Vec3f, 68>* head_landmarks = nullptr) {
  const Camera camera = FrameCamera(fp, shared, pose);
  std::optional<face::Similarity> sim;
  if (shared.known_cameras) sim = SharedSimilarity(shared, pose);
  const Vec3d camera_head = sim ? sim->Apply(camera.Center()) : camera.Center();
  std::array<Vec3f, 68> offsets;
  if (shared.dlib_convention) {
    offsets = DetectorLandmarkOffsets(shared.detector, camera_head.cast<float>());
  } else {
    offsets.fill(Vec3f::Zero());
  }
  const face::FaceModel& model = shared.cache.For(shape);
  const face::ExpressionState state = model.Prepare(ClampedExpression(expression, shared.max_expression));
  const std::array<Vec3f, 68> lm = model.Landmarks(state, offsets);
  if (head_landmarks) *head_landmarks = model.Landmarks(state);
  std::vector<std::optional<Vec2d>> out(kNumLandmarks);
  for (int i = 0; i < kNumLandmarks; ++i) {
    const Vec3d x = sim ? sim->ApplyInverse(lm[i].cast<double>()) : lm[i].cast<double>();
    if (const auto p = camera.Project(x)) out[i] = p->uv;
  }
  return out;
}

// Per-landmark errors in IOD (unweighted).
std::vector<double> Errors(const FrameProblem& fp, Shared& shared, const double* shape,
                           const double* expression, const double* pose) {
  const auto proj = Project(fp, shared, shape, expression, pose);
  std::vector<double> e(kNumLandmarks);
  for (int i = 0; i < kNumLandmarks; ++i)
    e[i] = proj[i] ? (*proj[i] - fp.frame->landmarks_2d[i].cast<double>()).norm() / fp.iod_px : 10.0;
  return e;
}

// The residuals of one frame over its (shape, expression, pose) blocks, with a Jacobian by finite
// differences whose steps suit each block (Ceres' relative steps vanish for weights at 0 and drown
// in the SDF's float noise): central differences, forward ones for an expression weight at its
// lower bound. Linearise() fixes, at the current parameters, what the differences hold constant.
// Not thread-safe (Linearise may keep state; the solver runs on one thread).
class FrameCost : public ceres::DynamicCostFunction {
 public:
  FrameCost(const FrameProblem* fp, Shared* shared, int num_residuals) : fp_(fp), shared_(shared) {
    AddParameterBlock(kShape);
    AddParameterBlock(kExpr);
    AddParameterBlock(shared->known_cameras ? kSharedPose : kPhotoPose);
    SetNumResiduals(num_residuals);
  }

  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override {
    Linearise(params);
    Residuals(params, residuals);
    if (!jacobians) return true;
    const int sizes[3] = {kShape, kExpr, shared_->known_cameras ? kSharedPose : kPhotoPose};
    const size_t n = static_cast<size_t>(num_residuals());
    std::vector<double> a(n), b(n);
    for (int block = 0; block < 3; ++block) {
      if (!jacobians[block]) continue;
      std::vector<double> x(params[block], params[block] + sizes[block]);
      double const* p[3] = {params[0], params[1], params[2]};
      p[block] = x.data();
      for (int j = 0; j < sizes[block]; ++j) {
        // Shape scales (~1), expression weights ([0, ~1]), angle-axis (radians), translation
        // (head or world units) and log scale.
        const double h = block == 0 ? 2e-3 : block == 1 ? 1e-2 : 1e-3;
        const double x0 = x[j];
        const bool forward = block == 1 && x0 < h;
        x[j] = x0 + h;
        Residuals(p, a.data());
        if (forward) {
          std::copy(residuals, residuals + n, b.begin());
        } else {
          x[j] = x0 - h;
          Residuals(p, b.data());
        }
        x[j] = x0;
        const double span = forward ? h : 2 * h;
        for (size_t r = 0; r < n; ++r) jacobians[block][r * sizes[block] + j] = (a[r] - b[r]) / span;
      }
    }
    return true;
  }

 protected:
  virtual void Linearise(double const* const* /*params*/) const {}
  virtual void Residuals(double const* const* params, double* residuals) const = 0;

  const FrameProblem* fp_;
  Shared* shared_;
};

// The 68 landmark residuals of one frame (IOD over the landmark noise).
class LandmarkCost : public FrameCost {
 public:
  LandmarkCost(const FrameProblem* fp, Shared* shared) : FrameCost(fp, shared, 2 * kNumLandmarks) {}

 private:
  void Residuals(double const* const* params, double* residuals) const override {
    const auto proj = Project(*fp_, *shared_, params[0], params[1], params[2]);
    for (int i = 0; i < kNumLandmarks; ++i) {
      const double w = fp_->weight[i] / shared_->landmark_sigma;
      Vec2d d(1.0, 1.0);  // behind the camera: a large, constant error
      if (proj[i]) d = (*proj[i] - fp_->frame->landmarks_2d[i].cast<double>()) / fp_->iod_px;
      residuals[2 * i] = w * d.x();
      residuals[2 * i + 1] = w * d.y();
    }
  }
};

// The head-frame ray through pixel `uv` of a frame for a pose.
Ray HeadRay(const FrameProblem& fp, const Shared& shared, const double* pose, const Vec2f& uv) {
  const Camera camera = FrameCamera(fp, shared, pose);
  const Ray world = camera.RayThrough(uv.x(), uv.y());
  if (!shared.known_cameras) return world;
  const face::Similarity sim = SharedSimilarity(shared, pose);
  return Ray{sim.Apply(world.origin.cast<double>()).cast<float>(),
             (sim.rotation * world.direction.cast<double>()).cast<float>()};
}

// The ray parameter of the ray's closest approach to the head's surface: the smallest distance
// bound over 64 samples around the head, refined by golden-section search. The head lies within
// 1.2 head units of the frame's origin.
float ClosestApproach(const face::FaceModel& model, const face::ExpressionState& state, const Ray& ray) {
  const float t_mid = -ray.origin.dot(ray.direction);
  constexpr int kSamples = 64;
  constexpr float kHalf = 1.2f, kStep = 2 * kHalf / (kSamples - 1);
  float best_t = t_mid, best = std::numeric_limits<float>::infinity();
  for (int i = 0; i < kSamples; ++i) {
    const float t = t_mid - kHalf + i * kStep;
    const float d = model.Distance(ray.At(t), state);
    if (d < best) best = d, best_t = t;
  }
  constexpr float kGolden = 0.618034f;
  float a = best_t - kStep, b = best_t + kStep;
  float c = b - kGolden * (b - a), e = a + kGolden * (b - a);
  float fc = model.Distance(ray.At(c), state), fe = model.Distance(ray.At(e), state);
  for (int i = 0; i < 20; ++i) {
    if (fc < fe) {
      b = e, e = c, fe = fc, c = b - kGolden * (b - a), fc = model.Distance(ray.At(c), state);
    } else {
      a = c, c = e, fc = fe, e = a + kGolden * (b - a), fe = model.Distance(ray.At(e), state);
    }
  }
  return 0.5f * (a + b);
}

// The silhouette residuals of one frame: for each edge point of its mask, the distance bound of the
// fitted surface at the closest approach of the point's ray (head units over the average head's
// IOD): 0 where the ray grazes the head, > 0 where it passes outside, < 0 where it cuts through.
// The finite differences hold the closest approach found for the current parameters fixed (the
// minimum's derivative is the distance's there: the envelope theorem).
class SilhouetteCost : public FrameCost {
 public:
  SilhouetteCost(const FrameProblem* fp, Shared* shared)
      : FrameCost(fp, shared, static_cast<int>(fp->frame->silhouette.size())) {}

  // The unweighted gaps (IOD) of every point, for the outlier pass and the report.
  // `contacts`, when given, gets each ray's closest approach (head frame).
  static std::vector<double> Gaps(const FrameProblem& fp, Shared& shared, const double* shape,
                                  const double* expression, const double* pose,
                                  std::vector<Vec3f>* contacts = nullptr) {
    const face::FaceModel& model = shared.cache.For(shape);
    const face::ExpressionState state = model.Prepare(ClampedExpression(expression, shared.max_expression));
    std::vector<double> gaps;
    for (const Vec2f& uv : fp.frame->silhouette) {
      const Ray ray = HeadRay(fp, shared, pose, uv);
      const Vec3f contact = ray.At(ClosestApproach(model, state, ray));
      gaps.push_back(model.Distance(contact, state) / shared.iod_head);
      if (contacts) contacts->push_back(contact);
    }
    return gaps;
  }

 private:
  void Linearise(double const* const* params) const override {
    const face::FaceModel& model = shared_->cache.For(params[0]);
    const face::ExpressionState state = model.Prepare(ClampedExpression(params[1], shared_->max_expression));
    const std::vector<Vec2f>& points = fp_->frame->silhouette;
    t_star_.assign(points.size(), 0.f);
    for (size_t i = 0; i < points.size(); ++i)
      if (fp_->silhouette_weight[i] > 0)
        t_star_[i] = ClosestApproach(model, state, HeadRay(*fp_, *shared_, params[2], points[i]));
  }

  void Residuals(double const* const* params, double* residuals) const override {
    const face::FaceModel& model = shared_->cache.For(params[0]);
    const face::ExpressionState state = model.Prepare(ClampedExpression(params[1], shared_->max_expression));
    const std::vector<Vec2f>& points = fp_->frame->silhouette;
    // A frame's points in use weigh together as much as 68 landmarks.
    const auto used = std::count_if(fp_->silhouette_weight.begin(), fp_->silhouette_weight.end(),
                                    [](double v) { return v > 0; });
    const double w =
        std::sqrt(double(kNumLandmarks) / double(std::max<ptrdiff_t>(used, 1))) / shared_->silhouette_sigma;
    for (size_t i = 0; i < points.size(); ++i) {
      if (fp_->silhouette_weight[i] == 0) {
        residuals[i] = 0;
        continue;
      }
      const Ray ray = HeadRay(*fp_, *shared_, params[2], points[i]);
      residuals[i] = w * model.Distance(ray.At(t_star_[i]), state) / shared_->iod_head;
    }
  }

  mutable std::vector<float> t_star_;  // Linearise's closest approaches
};

template <int N>
struct GaussianPrior {
  double mean;
  double inv_sigma;
  template <typename T>
  bool operator()(const T* x, T* residuals) const {
    for (int i = 0; i < N; ++i) residuals[i] = (x[i] - T(mean)) * T(inv_sigma);
    return true;
  }
};

// A Laplace prior on weights >= 0: cost sum(x) / scale, up to a constant, as the residuals
// sqrt(2 (x + kLaplaceOffset) / scale); the offset keeps their Jacobian finite at 0.
template <int N>
struct LaplacePrior {
  static constexpr double kLaplaceOffset = 0.02;
  double scale;
  template <typename T>
  bool operator()(const T* x, T* residuals) const {
    for (int i = 0; i < N; ++i) residuals[i] = sqrt(T(2.0) * (x[i] + T(kLaplaceOffset)) / T(scale));
    return true;
  }
};

Status CheckFrames(std::span<const TrackFrame> frames) {
  if (frames.empty()) return Status::Error("track fit: no frames");
  const bool known = frames[0].world_from_cam.has_value();
  for (size_t k = 0; k < frames.size(); ++k) {
    const TrackFrame& f = frames[k];
    const std::string where = "track fit: frame " + std::to_string(k) + ": ";
    if (f.landmarks_2d.size() != kNumLandmarks)
      return Status::Error(where + "landmarks_2d must have 68 points");
    for (const Vec2f& p : f.landmarks_2d)
      if (!p.allFinite()) return Status::Error(where + "landmarks_2d has a non-finite value");
    if (!(Iod2d(f.landmarks_2d) > 1e-6)) return Status::Error(where + "landmarks_2d: the eyes coincide");
    if (Status s = f.intrinsics.Validate(); !s.ok())
      return Status::Error(where + "intrinsics: " + s.message());
    for (const Vec2f& p : f.silhouette)
      if (!p.allFinite()) return Status::Error(where + "silhouette has a non-finite point");
    if (f.world_from_cam.has_value() != known)
      return Status::Error(where + "camera poses must be known for every frame or for none");
    if (f.world_from_cam) {
      if (Status s = ValidateRigid(*f.world_from_cam); !s.ok())
        return Status::Error(where + "camera pose: " + s.message());
    }
  }
  return Status::Ok();
}

// Photos: the head upright and facing the camera, turned by the eye line's roll, at the depth where
// the average head's IOD matches the observed one, its nose tip on the nose tip's ray.
void InitialPhotoPose(const TrackFrame& f, const face::FaceModel& average, double iod_head, Mat3d* rotation,
                      double* pose) {
  const Vec2d e = EyeCentre2d(f.landmarks_2d, 42) - EyeCentre2d(f.landmarks_2d, 36);
  const double roll = std::atan2(-e.y(), e.x());  // image v points down, camera y up
  *rotation = Eigen::AngleAxisd(roll, Vec3d::UnitZ()).toRotationMatrix();
  const Intrinsics& k = f.intrinsics;
  const double depth = k.fl_x * iod_head / Iod2d(f.landmarks_2d);
  const Vec2f nose = f.landmarks_2d[30];
  const Vec3d nose_cam = depth * Vec3d((nose.x() - k.cx) / k.fl_x, -(nose.y() - k.cy) / k.fl_y, -1.0);
  const Vec3d t = nose_cam - *rotation * average.NeutralLandmarks()[30].cast<double>();
  for (int i = 0; i < 3; ++i) pose[i] = 0, pose[3 + i] = t[i];
}

// The landmark (and silhouette) residuals of the frames `which`, their priors and bounds.
void AddLandmarkBlocks(ceres::Problem& cp, std::vector<FrameProblem>& problems, const std::vector<int>& which,
                       Shared& shared, const TrackFitOptions& options, bool fit_shape, bool fit_pose,
                       Solution* s) {
  for (int k : which) {
    double* pose = shared.known_cameras ? s->pose[0].data() : s->pose[k].data();
    cp.AddResidualBlock(new LandmarkCost(&problems[k], &shared), nullptr, s->shape.data(),
                        s->expression[k].data(), pose);
    if (shared.use_silhouettes && !problems[k].frame->silhouette.empty())
      cp.AddResidualBlock(new SilhouetteCost(&problems[k], &shared), nullptr, s->shape.data(),
                          s->expression[k].data(), pose);
    cp.AddResidualBlock(new ceres::AutoDiffCostFunction<GaussianPrior<kExpr>, kExpr, kExpr>(
                            new GaussianPrior<kExpr>{0.0, 1.0 / options.expression_prior_sigma}),
                        nullptr, s->expression[k].data());
    if (options.expression_prior_laplace > 0)
      cp.AddResidualBlock(new ceres::AutoDiffCostFunction<LaplacePrior<kExpr>, kExpr, kExpr>(
                              new LaplacePrior<kExpr>{options.expression_prior_laplace}),
                          nullptr, s->expression[k].data());
    for (int i = 0; i < kExpr; ++i) {
      cp.SetParameterLowerBound(s->expression[k].data(), i, 0.0);
      cp.SetParameterUpperBound(s->expression[k].data(), i, options.max_expression);
    }
    if (!fit_pose) cp.SetParameterBlockConstant(pose);
  }
  cp.AddResidualBlock(new ceres::AutoDiffCostFunction<GaussianPrior<kShape>, kShape, kShape>(
                          new GaussianPrior<kShape>{1.0, 1.0 / options.shape_prior_sigma}),
                      nullptr, s->shape.data());
  for (int i = 0; i < kShape; ++i) {  // keep the head buildable
    cp.SetParameterLowerBound(s->shape.data(), i, options.shape_min);
    cp.SetParameterUpperBound(s->shape.data(), i, options.shape_max);
  }
  if (!fit_shape) cp.SetParameterBlockConstant(s->shape.data());
}

Status RunSolver(ceres::Problem& cp, const TrackFitOptions& options, Solution* s) {
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_SCHUR;
  so.max_num_iterations = options.max_iterations;
  so.num_threads = 1;  // deterministic (and the model cache is not thread-safe)
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &cp, &summary);
  if (!summary.IsSolutionUsable()) return Status::Error("track fit: the solver failed: " + summary.message);
  s->iterations += static_cast<int>(summary.iterations.size());
  return Status::Ok();
}

// One Levenberg-Marquardt solve over the frames `which` (outlier weights as they stand).
Status Solve(std::vector<FrameProblem>& problems, const std::vector<int>& which, Shared& shared,
             const TrackFitOptions& options, bool fit_shape, bool fit_pose, Solution* s) {
  ceres::Problem cp;
  AddLandmarkBlocks(cp, problems, which, shared, options, fit_shape, fit_pose, s);
  return RunSolver(cp, options, s);
}

const double* PoseOf(const Solution& s, const Shared& shared, int k) {
  return shared.known_cameras ? s.pose[0].data() : s.pose[k].data();
}

// Drops (weight 0) the landmarks of `which` farther than outlier_iod and 3x the median error;
// returns how many were newly dropped.
int DropOutliers(std::vector<FrameProblem>& problems, const std::vector<int>& which, Shared& shared,
                 const TrackFitOptions& options, const Solution& s) {
  std::vector<std::vector<double>> errors;
  std::vector<double> all;
  for (int k : which) {
    errors.push_back(
        Errors(problems[k], shared, s.shape.data(), s.expression[k].data(), PoseOf(s, shared, k)));
    all.insert(all.end(), errors.back().begin(), errors.back().end());
  }
  std::nth_element(all.begin(), all.begin() + all.size() / 2, all.end());
  const double cut = std::max(options.outlier_iod, 3.0 * all[all.size() / 2]);
  int removed = 0;
  for (size_t j = 0; j < which.size(); ++j) {
    FrameProblem& fp = problems[which[j]];
    for (int i = 0; i < kNumLandmarks; ++i)
      if (errors[j][i] > cut && fp.weight[i] > 0) fp.weight[i] = 0, ++removed;
  }
  // Silhouette points likewise, on their own median (hair beyond the skull, a collar, a hand).
  std::vector<std::vector<double>> gaps;
  std::vector<double> all_gaps;
  for (int k : which) {
    if (!shared.use_silhouettes) break;
    gaps.push_back(SilhouetteCost::Gaps(problems[k], shared, s.shape.data(), s.expression[k].data(),
                                        PoseOf(s, shared, k)));
    for (double& g : gaps.back()) all_gaps.push_back(g = std::abs(g));
  }
  if (all_gaps.empty()) return removed;
  std::nth_element(all_gaps.begin(), all_gaps.begin() + all_gaps.size() / 2, all_gaps.end());
  const double gap_cut = std::max(options.outlier_iod, 3.0 * all_gaps[all_gaps.size() / 2]);
  for (size_t j = 0; j < which.size(); ++j) {
    FrameProblem& fp = problems[which[j]];
    for (size_t i = 0; i < gaps[j].size(); ++i)
      if (gaps[j][i] > gap_cut && fp.silhouette_weight[i] > 0) fp.silhouette_weight[i] = 0, ++removed;
  }
  return removed;
}

// Keeps the silhouette points that the landmark fit's head explains: within silhouette_max_gap_iod
// of its surface (farther: hair, a hat, a collar, a hand) and, with silhouette_face_only, touching
// it between the chin and the brows (the face's own outline: a real head's crown is hair and its
// neck runs into clothes, neither of which the face model has).
void SelectSilhouettePoints(std::vector<FrameProblem>& problems, Shared& shared,
                            const TrackFitOptions& options, const Solution& s) {
  for (size_t k = 0; k < problems.size(); ++k) {
    FrameProblem& fp = problems[k];
    if (fp.frame->silhouette.empty()) continue;
    const double* pose = PoseOf(s, shared, static_cast<int>(k));
    std::vector<Vec3f> contacts;
    const std::vector<double> gaps =
        SilhouetteCost::Gaps(fp, shared, s.shape.data(), s.expression[k].data(), pose, &contacts);
    const face::FaceModel& model = shared.cache.For(s.shape.data());
    const std::array<Vec3f, 68> lm =
        model.Landmarks(model.Prepare(ClampedExpression(s.expression[k].data(), shared.max_expression)));
    float brow_y = 0;
    for (int i = 17; i <= 26; ++i) brow_y += lm[i].y() / 10.f;
    const float chin_y = lm[8].y();
    for (size_t i = 0; i < gaps.size(); ++i) {
      const bool near = std::abs(gaps[i]) <= options.silhouette_max_gap_iod;
      const bool face_band = contacts[i].y() >= chin_y && contacts[i].y() <= brow_y;
      fp.silhouette_weight[i] = near && (face_band || !options.silhouette_face_only) ? 1.0 : 0.0;
    }
  }
}

// Pose-only warm start, then the joint solve with one outlier pass.
Status SolveFrames(std::vector<FrameProblem>& problems, const std::vector<int>& which, Shared& shared,
                   const TrackFitOptions& options, bool fit_shape, Solution* s) {
  ICEF_RETURN_IF_ERROR(Solve(problems, which, shared, options, /*fit_shape=*/false, /*fit_pose=*/true, s));
  for (int pass = 0; pass < 2; ++pass) {
    ICEF_RETURN_IF_ERROR(Solve(problems, which, shared, options, fit_shape, /*fit_pose=*/true, s));
    if (pass == 0 && DropOutliers(problems, which, shared, options, *s) == 0) break;
  }
  return Status::Ok();
}

}  // namespace internal

using namespace internal;  // NOLINT(google-build-using-namespace): this file's own helpers

std::string TrackedFrame::ToString() const {
  std::ostringstream os;
  const Vec3d ypr = YawPitchRollDeg();
  os << "TrackedFrame(yaw=" << ypr.x() << ", pitch=" << ypr.y() << ", roll=" << ypr.z()
     << ", rms_iod=" << rms_iod << ", landmarks_used=" << landmarks_used << ")";
  return os.str();
}

Vec3d TrackedFrame::YawPitchRollDeg() const {
  // cam_from_head = Rz(roll) Rx(-pitch) Ry(yaw), angles about the camera's axes (as icef synth
  // --photos draws them).
  const Mat3d r = cam_from_head.block<3, 3>(0, 0);
  const double pitch = -std::asin(std::clamp(r(2, 1), -1.0, 1.0));
  const double yaw = std::atan2(-r(2, 0), r(2, 2));
  const double roll = std::atan2(-r(0, 1), r(1, 1));
  return Vec3d(yaw, pitch, roll) * 180.0 / M_PI;
}

Status TrackFitOptions::Validate() const {
  if (!(shape_min > 0 && shape_min < 1 && shape_max > 1 && std::isfinite(shape_max)))
    return Status::Error("shape bounds must satisfy 0 < shape_min < 1 < shape_max");
  if (!(shape_prior_sigma > 0) || !std::isfinite(shape_prior_sigma))
    return Status::Error("shape_prior_sigma must be a finite number > 0");
  if (!(expression_prior_sigma > 0) || !std::isfinite(expression_prior_sigma))
    return Status::Error("expression_prior_sigma must be a finite number > 0");
  if (!(expression_prior_laplace >= 0) || !std::isfinite(expression_prior_laplace) ||
      !(photometric_expression_prior_laplace >= 0) || !std::isfinite(photometric_expression_prior_laplace))
    return Status::Error(
        "expression_prior_laplace and photometric_expression_prior_laplace must be finite numbers >= 0");
  if (!(max_expression > 0) || !std::isfinite(max_expression))
    return Status::Error("max_expression must be > 0");
  if (!(jaw_line_weight >= 0) || jaw_line_weight > 1)
    return Status::Error("jaw_line_weight must be in [0, 1]");
  if (max_iterations < 1) return Status::Error("max_iterations must be >= 1");
  if (!(outlier_iod > 0)) return Status::Error("outlier_iod must be > 0");
  if (!(landmark_sigma_iod > 0) || !std::isfinite(landmark_sigma_iod))
    return Status::Error("landmark_sigma_iod must be a finite number > 0");
  if (!(silhouette_sigma_iod > 0) || !std::isfinite(silhouette_sigma_iod))
    return Status::Error("silhouette_sigma_iod must be a finite number > 0");
  if (!(silhouette_max_gap_iod > 0)) return Status::Error("silhouette_max_gap_iod must be > 0");
  if (!(photometric_weight >= 0) || !std::isfinite(photometric_weight))
    return Status::Error("photometric_weight must be a finite number >= 0");
  if (!(photometric_max_rms > 0)) return Status::Error("photometric_max_rms must be > 0");
  if (!(photometric_sigma > 0) || !std::isfinite(photometric_sigma))
    return Status::Error("photometric_sigma must be a finite number > 0");
  if (!(photometric_expression_prior_sigma > 0) || !std::isfinite(photometric_expression_prior_sigma))
    return Status::Error("photometric_expression_prior_sigma must be a finite number > 0");
  if (photometric_points < 1) return Status::Error("photometric_points must be >= 1");
  if (Status s = style.Validate(); !s.ok()) return Status::Error("style: " + s.message());
  if (!(photometric_blur_coarse_iod >= 0) || !(photometric_blur_fine_iod >= 0) ||
      !std::isfinite(photometric_blur_coarse_iod) || !std::isfinite(photometric_blur_fine_iod))
    return Status::Error(
        "photometric_blur_coarse_iod and photometric_blur_fine_iod must be finite numbers >= 0");
  return Status::Ok();
}

std::string TrackFitOptions::ToString() const {
  std::ostringstream os;
  os << "TrackFitOptions(shape_prior_sigma=" << shape_prior_sigma << ", shape_min=" << shape_min
     << ", shape_max=" << shape_max << ", expression_prior_sigma=" << expression_prior_sigma
     << ", max_expression=" << max_expression << ", jaw_line_weight=" << jaw_line_weight
     << ", max_iterations=" << max_iterations << ", outlier_iod=" << outlier_iod
     << ", dlib_convention=" << dlib_convention << ", detector=" << LandmarkDetectorName(detector)
     << ", landmark_sigma_iod=" << landmark_sigma_iod << ", silhouette_sigma_iod=" << silhouette_sigma_iod
     << ", silhouette_max_gap_iod=" << silhouette_max_gap_iod
     << ", silhouette_face_only=" << silhouette_face_only << ", photometric_weight=" << photometric_weight
     << ", photometric_hold_similarity=" << photometric_hold_similarity
     << ", photometric_sigma=" << photometric_sigma
     << ", expression_prior_laplace=" << expression_prior_laplace
     << ", photometric_expression_prior_sigma=" << photometric_expression_prior_sigma
     << ", photometric_expression_prior_laplace=" << photometric_expression_prior_laplace
     << ", photometric_points=" << photometric_points << ", photometric_max_rms=" << photometric_max_rms
     << ", photometric_blur_iod=[" << photometric_blur_coarse_iod << ", " << photometric_blur_fine_iod
     << "], style=" << style.ToString() << ")";
  return os.str();
}

std::string TrackFit::BriefReport() const {
  std::ostringstream os;
  os.precision(3);
  os << "track fit: " << frames.size() << " images, landmark RMS " << rms_iod << " IOD (max " << max_iod
     << "), " << iterations << " iterations, photometric refit " << photometric;
  if (silhouettes.rfind("not used", 0) == 0) os << ", silhouette refit " << silhouettes;
  return os.str();
}

Result<TrackFit> FitTrack(std::span<const TrackFrame> frames, const TrackFitOptions& options) {
  ICEF_RETURN_IF_ERROR(options.Validate().WithContext("track fit options"));
  ICEF_RETURN_IF_ERROR(CheckFrames(frames));
  const int n = static_cast<int>(frames.size());
  const face::FaceModel average(face::ShapeParams::Average());
  const double iod_head = face::InterOcularDistance(average.NeutralLandmarks());

  Shared shared;
  shared.cache.SetStyle(options.style);
  shared.max_expression = options.max_expression;
  shared.known_cameras = frames[0].world_from_cam.has_value();
  shared.dlib_convention = options.dlib_convention;
  shared.detector = options.detector;
  shared.landmark_sigma = options.landmark_sigma_iod;
  shared.silhouette_sigma = options.silhouette_sigma_iod;
  shared.iod_head = iod_head;
  std::vector<FrameProblem> problems(n);
  Solution s;
  s.shape.fill(1.0);
  s.expression.assign(n, {});
  for (auto& e : s.expression) e.fill(0.0);
  for (int k = 0; k < n; ++k) {
    problems[k].frame = &frames[k];
    problems[k].iod_px = Iod2d(frames[k].landmarks_2d);
    problems[k].weight.fill(1.0);
    problems[k].silhouette_weight.assign(frames[k].silhouette.size(), 1.0);
    for (int i = 0; i <= 16; ++i) problems[k].weight[i] = options.jaw_line_weight;
  }
  if (shared.known_cameras) {
    // The head_from_world of the average neutral head (face/face_fit.h's 2D initialisation).
    std::vector<face::FitFrame> fit_frames(n);
    for (int k = 0; k < n; ++k) {
      fit_frames[k].expression.assign(kExpr, 0.f);
      fit_frames[k].landmarks_2d = frames[k].landmarks_2d;
      fit_frames[k].camera = Camera(frames[k].intrinsics, *frames[k].world_from_cam);
    }
    face::FaceFitOptions fo;
    fo.fit_shape = false;
    ICEF_ASSIGN_OR_RETURN(const face::FaceFit initial, face::FitFaceModel(fit_frames, fo));
    shared.base = initial.head_from_world;
    s.pose = {
        {0, 0, 0, shared.base.translation.x(), shared.base.translation.y(), shared.base.translation.z(), 0}};
  } else {
    s.pose.assign(n, std::vector<double>(kPhotoPose));
    for (int k = 0; k < n; ++k)
      InitialPhotoPose(frames[k], average, iod_head, &problems[k].base_rotation, s.pose[k].data());
  }

  // The joint solve over (evenly spaced) frames, then every other frame on the shape found.
  std::vector<int> joint, rest;
  const int stride = (n + kMaxJointFrames - 1) / kMaxJointFrames;
  for (int k = 0; k < n; ++k) (k % stride == 0 ? joint : rest).push_back(k);
  const auto solve_all = [&]() -> Status {
    ICEF_RETURN_IF_ERROR(SolveFrames(problems, joint, shared, options, /*fit_shape=*/true, &s));
    for (int k : rest) {
      if (shared.known_cameras) {  // the shared pose stays: expression only
        ICEF_RETURN_IF_ERROR(Solve(problems, {k}, shared, options, false, false, &s));
      } else {
        ICEF_RETURN_IF_ERROR(SolveFrames(problems, {k}, shared, options, /*fit_shape=*/false, &s));
      }
    }
    return Status::Ok();
  };
  // The landmarks alone first: the silhouette residuals have local minima far from the pose.
  ICEF_RETURN_IF_ERROR(solve_all());
  if (std::any_of(frames.begin(), frames.end(), [](const TrackFrame& f) { return !f.silhouette.empty(); })) {
    shared.use_silhouettes = true;
    SelectSilhouettePoints(problems, shared, options, s);
    const bool any = std::any_of(problems.begin(), problems.end(), [](const FrameProblem& fp) {
      return std::any_of(fp.silhouette_weight.begin(), fp.silhouette_weight.end(),
                         [](double w) { return w > 0; });
    });
    if (any) {
      // The silhouettes can pull the fit into a degenerate head (a shape scale on its bound, the
      // pose turned to match: docs/tracking.md); then the landmarks' fit stays.
      const Solution landmark_fit = s;
      ICEF_RETURN_IF_ERROR(solve_all());
      s.silhouette_note = "used";
      for (int i = 0; i < kShape; ++i) {
        if (s.shape[i] > options.shape_min + 1e-3 && s.shape[i] < options.shape_max - 1e-3) continue;
        std::ostringstream why;
        why.precision(3);
        why << "not used: the head's " << face::kShapeParamNames[i] << " ran to its bound " << s.shape[i]
            << "; the landmarks' fit is kept";
        const int iterations = s.iterations;
        s = landmark_fit;
        s.iterations = iterations;
        s.silhouette_note = why.str();
        shared.use_silhouettes = false;
        for (FrameProblem& fp : problems)
          std::fill(fp.silhouette_weight.begin(), fp.silhouette_weight.end(), 0.0);
        break;
      }
    }
  }
  // Then the images, when every frame has one and there are two to compare.
  const bool photos =
      std::all_of(frames.begin(), frames.end(), [](const TrackFrame& f) { return f.photo != nullptr; });
  if (options.photometric_weight > 0 && photos && n >= 2)
    ICEF_RETURN_IF_ERROR(PhotometricRefit(problems, shared, options, &s));

  TrackFit fit;
  fit.iterations = s.iterations;
  fit.photometric = s.photometric_note.empty() ? "off" : s.photometric_note;
  fit.silhouettes = s.silhouette_note.empty() ? "off" : s.silhouette_note;
  fit.shape = face::ShapeParams::FromArray([&] {
    std::array<float, kShape> v;
    for (int i = 0; i < kShape; ++i) v[i] = static_cast<float>(s.shape[i]);
    return v;
  }());
  if (shared.known_cameras) fit.head_from_world = SharedSimilarity(shared, s.pose[0].data());
  double sum2 = 0;
  int used_all = 0;
  for (int k = 0; k < n; ++k) {
    TrackedFrame tf;
    const double* pose = PoseOf(s, shared, k);
    tf.expression = ClampedExpression(s.expression[k].data(), options.max_expression);
    const auto proj =
        Project(problems[k], shared, s.shape.data(), s.expression[k].data(), pose, &tf.landmarks_head);
    const Camera camera = FrameCamera(problems[k], shared, pose);
    tf.cam_from_head = camera.cam_from_world();
    if (fit.head_from_world) {  // cam_from_world * world_from_head
      Mat4d world_from_head = Mat4d::Identity();
      const face::Similarity& h = *fit.head_from_world;
      world_from_head.block<3, 3>(0, 0) = h.rotation.transpose() / h.scale;
      world_from_head.block<3, 1>(0, 3) = -h.rotation.transpose() * h.translation / h.scale;
      tf.cam_from_head = camera.cam_from_world() * world_from_head;
    }
    const std::vector<double> e = Errors(problems[k], shared, s.shape.data(), s.expression[k].data(), pose);
    double frame_sum2 = 0;
    for (int i = 0; i < kNumLandmarks; ++i) {
      tf.projected.push_back(proj[i] ? proj[i]->cast<float>() : Vec2f(NAN, NAN));
      tf.max_iod = std::max(tf.max_iod, e[i]);
      if (problems[k].weight[i] > 0) frame_sum2 += e[i] * e[i], ++tf.landmarks_used;
    }
    tf.rms_iod = std::sqrt(frame_sum2 / std::max(tf.landmarks_used, 1));
    const std::vector<double> gaps =
        SilhouetteCost::Gaps(problems[k], shared, s.shape.data(), s.expression[k].data(), pose);
    double gap_sum2 = 0;
    for (size_t i = 0; i < gaps.size(); ++i)
      if (problems[k].silhouette_weight[i] > 0) {
        gap_sum2 += gaps[i] * gaps[i], ++tf.silhouette_used;
        tf.silhouette_points.push_back(frames[k].silhouette[i]);
      }
    tf.silhouette_rms_iod = std::sqrt(gap_sum2 / std::max(tf.silhouette_used, 1));
    if (!s.photometric_rms.empty())
      tf.photometric_rms = s.photometric_rms[k], tf.photometric_used = s.photometric_used[k];
    sum2 += frame_sum2;
    used_all += tf.landmarks_used;
    fit.max_iod = std::max(fit.max_iod, tf.max_iod);
    fit.frames.push_back(std::move(tf));
  }
  fit.rms_iod = std::sqrt(sum2 / std::max(used_all, 1));
  return fit;
}

}  // namespace icef::track
