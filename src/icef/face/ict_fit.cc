#include "icef/face/ict_fit.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <utility>

namespace icef::face {
namespace {

constexpr int kNumLandmarks = face::IctModel::kNumLandmarks;
constexpr int kMinLandmarks = 6;            // fewer than this and the pose is not determined
constexpr double kMinDepth = 1e-3;          // cm: landmarks nearer the camera plane make a step fail
constexpr double kLaplaceSmoothing = 0.02;  // the Laplace prior is smooth below this weight
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// The model's 68 landmark rows, linear in the coefficients (head frame, cm): row 3 i + k is
// coordinate k of landmark i. Only these rows are ever evaluated, never the full mesh.
struct LandmarkBasis {
  std::array<bool, kNumLandmarks> present{};  // the model has a vertex for the landmark
  VecXd neutral;                              // [204]
  RowMatrix identity;                         // [204, num_identity]
  RowMatrix expression;                       // [204, num_expressions]
  std::vector<std::pair<int, int>> pairs;     // (_L, _R) expression indices, gaze excepted

  int num_identity() const { return static_cast<int>(identity.cols()); }
  int num_expressions() const { return static_cast<int>(expression.cols()); }
  VecXd Positions(const double* identity_coeffs, const double* expression_weights) const {
    return neutral + identity * Eigen::Map<const VecXd>(identity_coeffs, num_identity()) +
           expression * Eigen::Map<const VecXd>(expression_weights, num_expressions());
  }
};

LandmarkBasis MakeBasis(const face::IctModel& model, int num_identity) {
  LandmarkBasis b;
  const int num_expressions = model.num_expressions();
  b.neutral = VecXd::Zero(3 * kNumLandmarks);
  b.identity = RowMatrix::Zero(3 * kNumLandmarks, num_identity);
  b.expression = RowMatrix::Zero(3 * kNumLandmarks, num_expressions);
  for (int i = 0; i < kNumLandmarks; ++i) {
    const int v = model.landmark_vertices()[i];
    b.present[i] = v >= 0;
    if (v < 0) continue;
    b.neutral.segment<3>(3 * i) = model.neutral()[v].cast<double>();
    for (int j = 0; j < num_identity; ++j)
      b.identity.block<3, 1>(3 * i, j) = model.IdentityMode(j)[v].cast<double>();
    for (int e = 0; e < num_expressions; ++e)
      b.expression.block<3, 1>(3 * i, e) = model.ExpressionDelta(e)[v].cast<double>();
  }
  const std::vector<std::string>& names = model.expression_names();
  for (int e = 0; e < num_expressions; ++e) {
    const std::string& n = names[e];
    if (n.size() < 3 || n.compare(n.size() - 2, 2, "_L") != 0) continue;
    if (n.rfind("eyeLook", 0) == 0) continue;  // gaze: looking left is eyeLookOut_L + eyeLookIn_R
    const auto right = std::find(names.begin(), names.end(), n.substr(0, n.size() - 2) + "_R");
    if (right != names.end()) b.pairs.emplace_back(e, static_cast<int>(right - names.begin()));
  }
  return b;
}

// Everything one photo's residuals need besides the parameters.
struct PhotoData {
  Intrinsics intrinsics;
  std::array<Vec2d, kNumLandmarks> observed{};
  std::array<double, kNumLandmarks> weight{};  // observation x jaw line x model has it; 0 = unused
  double iod_px = 1;
};

// One photo's unknowns besides the shared identity: pointers into Unknowns' slab.
struct PhotoParams {
  double* expression;   // [num_expressions]
  double* rotation;     // [3] angle-axis of cam_from_head
  double* translation;  // [3] cm, camera frame
};

// Every unknown in one slab: identity [num_identity], then per photo expression, angle-axis and
// translation. Ceres orders blocks by address where it eliminates them (the Schur complement), so
// one slab keeps that order, and with it every rounding, the same from run to run.
class Unknowns {
 public:
  Unknowns(int num_identity, int num_expressions, int num_photos)
      : num_identity_(num_identity),
        num_expressions_(num_expressions),
        slab_(num_identity + static_cast<size_t>(num_photos) * (num_expressions + 6), 0.0) {}
  double* identity() { return slab_.data(); }
  PhotoParams photo(int k) {
    double* p = slab_.data() + num_identity_ + static_cast<size_t>(k) * (num_expressions_ + 6);
    return {p, p + num_expressions_, p + num_expressions_ + 3};
  }
  int num_photos() const { return static_cast<int>((slab_.size() - num_identity_) / (num_expressions_ + 6)); }

 private:
  int num_identity_, num_expressions_;
  std::vector<double> slab_;
};

// Image coordinates of a camera-frame point (math/camera.h: u = cx + fl_x x / depth,
// v = cy - fl_y y / depth, depth = -z) and d(u, v)/d(point).
Vec2d ProjectCam(const Intrinsics& k, const Vec3d& p, Eigen::Matrix<double, 2, 3>* d_point) {
  const double z = p.z();
  if (d_point) {
    *d_point << -k.fl_x / z, 0, k.fl_x * p.x() / (z * z),  //
        0, k.fl_y / z, -k.fl_y * p.y() / (z * z);
  }
  return Vec2d(k.cx - k.fl_x * p.x() / z, k.cy + k.fl_y * p.y() / z);
}

Mat3d RotationOf(const double* angle_axis) {
  Mat3d r;  // Eigen's default column-major storage is Ceres' layout
  ceres::AngleAxisToRotationMatrix(angle_axis, r.data());
  return r;
}

// The rotation of an angle-axis and its derivatives d R / d angle_axis[k] (Ceres' jets).
void RotationAndDerivatives(const double* angle_axis, Mat3d* r, std::array<Mat3d, 3>* dr) {
  using Jet = ceres::Jet<double, 3>;
  Jet aa[3], m[9];
  for (int k = 0; k < 3; ++k) aa[k] = Jet(angle_axis[k], k);
  ceres::AngleAxisToRotationMatrix(aa, m);  // column-major
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) {
      (*r)(row, c) = m[3 * c + row].a;
      for (int k = 0; k < 3; ++k) (*dr)[k](row, c) = m[3 * c + row].v[k];
    }
}

// The landmark residuals of one photo, (projection - observed) * weight / (sigma * IOD), with
// their Jacobian. The camera-frame point of a head point h is A (s R h + t) + b: with the photo's
// own pose (A = I, b = 0, s = 1) over the blocks (identity [N], expression [E], angle-axis of R
// [3], t [3] cm); with a known camera (A, b = its rigid cam_from_world, world units) and the head
// placed by one similarity for all photos, x_world = s R h + t, over (identity, expression,
// angle-axis, t [3] world units, log s [1]). The projection does not see the camera frame's units.
class LandmarkCost : public ceres::CostFunction {
 public:
  LandmarkCost(const LandmarkBasis* basis, const PhotoData* photo, double sigma_iod,
               const std::optional<Mat4d>& cam_from_world = std::nullopt)
      : basis_(basis),
        photo_(photo),
        known_camera_(cam_from_world.has_value()),
        cam_rotation_(known_camera_ ? Mat3d(cam_from_world->block<3, 3>(0, 0)) : Mat3d::Identity()),
        cam_translation_(known_camera_ ? Vec3d(cam_from_world->block<3, 1>(0, 3)) : Vec3d::Zero()),
        scale_(1.0 / (sigma_iod * photo->iod_px)) {
    set_num_residuals(2 * kNumLandmarks);
    *mutable_parameter_block_sizes() = {basis->num_identity(), basis->num_expressions(), 3, 3};
    if (known_camera_) mutable_parameter_block_sizes()->push_back(1);
  }

  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override {
    const int n = basis_->num_identity(), ne = basis_->num_expressions();
    Mat3d r;
    std::array<Mat3d, 3> dr;
    RotationAndDerivatives(params[2], &r, &dr);
    const Vec3d t(params[3][0], params[3][1], params[3][2]);
    const double head_scale = known_camera_ ? std::exp(params[4][0]) : 1.0;
    const VecXd x = basis_->Positions(params[0], params[1]);
    const int sizes[5] = {n, ne, 3, 3, 1};
    for (int b = 0; b < (known_camera_ ? 5 : 4); ++b)
      if (jacobians && jacobians[b]) std::fill_n(jacobians[b], 2 * kNumLandmarks * sizes[b], 0.0);
    const Mat3d cam_head = head_scale * cam_rotation_ * r;  // d cam / d head
    for (int i = 0; i < kNumLandmarks; ++i) {
      residuals[2 * i] = residuals[2 * i + 1] = 0;
      if (photo_->weight[i] == 0) continue;
      const Vec3d head = x.segment<3>(3 * i);
      const Vec3d cam = cam_head * head + cam_rotation_ * t + cam_translation_;
      if (cam.z() > -kMinDepth) return false;  // at or behind the camera: the step fails
      Eigen::Matrix<double, 2, 3> d_cam;
      const double s = scale_ * photo_->weight[i];
      const Vec2d e = s * (ProjectCam(photo_->intrinsics, cam, &d_cam) - photo_->observed[i]);
      residuals[2 * i] = e.x();
      residuals[2 * i + 1] = e.y();
      if (!jacobians) continue;
      const Eigen::Matrix<double, 2, 3> d_head = s * d_cam * cam_head;
      if (jacobians[0])
        Eigen::Map<RowMatrix>(jacobians[0], 2 * kNumLandmarks, n).middleRows<2>(2 * i) =
            d_head * basis_->identity.middleRows<3>(3 * i);
      if (jacobians[1])
        Eigen::Map<RowMatrix>(jacobians[1], 2 * kNumLandmarks, ne).middleRows<2>(2 * i) =
            d_head * basis_->expression.middleRows<3>(3 * i);
      for (int k = 0; k < 3 && jacobians[2]; ++k) {
        const Vec2d d = s * d_cam * (head_scale * cam_rotation_ * (dr[k] * head));
        jacobians[2][6 * i + k] = d.x();
        jacobians[2][6 * i + 3 + k] = d.y();
      }
      if (jacobians[3]) {
        const Eigen::Matrix<double, 2, 3> d_t = s * d_cam * cam_rotation_;
        for (int k = 0; k < 3; ++k) {
          jacobians[3][6 * i + k] = d_t(0, k);
          jacobians[3][6 * i + 3 + k] = d_t(1, k);
        }
      }
      if (known_camera_ && jacobians[4]) {
        const Vec2d d = d_head * head;
        jacobians[4][2 * i] = d.x();
        jacobians[4][2 * i + 1] = d.y();
      }
    }
    return true;
  }

 private:
  const LandmarkBasis* basis_;
  const PhotoData* photo_;
  bool known_camera_;
  Mat3d cam_rotation_;
  Vec3d cam_translation_;
  double scale_;
};

// A Gaussian prior toward 0 on one block: residuals x / sigma.
class GaussianPrior : public ceres::CostFunction {
 public:
  GaussianPrior(int size, double sigma) : inv_sigma_(1.0 / sigma) {
    set_num_residuals(size);
    *mutable_parameter_block_sizes() = {size};
  }
  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override {
    const int n = num_residuals();
    for (int i = 0; i < n; ++i) residuals[i] = params[0][i] * inv_sigma_;
    if (jacobians && jacobians[0])
      Eigen::Map<RowMatrix>(jacobians[0], n, n) = RowMatrix::Identity(n, n) * inv_sigma_;
    return true;
  }

 private:
  double inv_sigma_;
};

// The priors of one photo's expression weights (all >= 0), as residuals: beta / sigma (Gaussian);
// with a Laplace scale L, a smoothed L1 cost 2 s softplus(beta / s) / L (s = kLaplaceSmoothing:
// 2 beta / L up to a constant above s, smooth everywhere, so finite differences may cross 0) as
// residuals sqrt(2 s softplus(beta / s) / L), never 0; (beta_L - beta_R) / symmetry_sigma for
// every _L/_R pair.
class ExpressionPrior : public ceres::CostFunction {
 public:
  ExpressionPrior(const LandmarkBasis* basis, const IctFitOptions& o)
      : basis_(basis),
        inv_sigma_(1.0 / o.expression_prior_sigma),
        laplace_(o.expression_prior_laplace),
        inv_symmetry_(1.0 / o.symmetry_sigma) {
    const int ne = basis->num_expressions();
    const int pairs = std::isinf(o.symmetry_sigma) ? 0 : static_cast<int>(basis->pairs.size());
    set_num_residuals(ne * (laplace_ > 0 ? 2 : 1) + pairs);
    *mutable_parameter_block_sizes() = {ne};
  }

  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override {
    const int ne = basis_->num_expressions(), nr = num_residuals();
    const double* beta = params[0];
    double* jac = jacobians ? jacobians[0] : nullptr;
    if (jac) std::fill_n(jac, nr * ne, 0.0);
    int row = 0;
    for (int e = 0; e < ne; ++e, ++row) {
      residuals[row] = beta[e] * inv_sigma_;
      if (jac) jac[row * ne + e] = inv_sigma_;
    }
    for (int e = 0; e < ne && laplace_ > 0; ++e, ++row) {
      const double t = beta[e] / kLaplaceSmoothing;
      const double softplus = t > 30 ? t : std::log1p(std::exp(t));
      const double r = std::sqrt(2.0 * kLaplaceSmoothing * softplus / laplace_);
      residuals[row] = r;
      if (jac) jac[row * ne + e] = 1.0 / ((1.0 + std::exp(-t)) * laplace_ * r);  // sigmoid(t) / (L r)
    }
    for (size_t p = 0; row < nr; ++p, ++row) {
      const auto [left, right] = basis_->pairs[p];
      residuals[row] = (beta[left] - beta[right]) * inv_symmetry_;
      if (jac) jac[row * ne + left] = inv_symmetry_, jac[row * ne + right] = -inv_symmetry_;
    }
    return true;
  }

 private:
  const LandmarkBasis* basis_;
  double inv_sigma_, laplace_, inv_symmetry_;
};

Vec2d EyeCentre(const PhotoData& d, int first, int* count) {
  Vec2d c = Vec2d::Zero();
  *count = 0;
  for (int i = first; i < first + 6; ++i)
    if (d.weight[i] > 0) c += d.observed[i], ++*count;
  return *count > 0 ? Vec2d(c / *count) : c;
}

// Checks one photo and gathers what its residuals need. IOD: between the centres of the eyes'
// landmarks present (0 when an eye has none: InitialPose estimates it then).
Result<PhotoData> MakePhotoData(const IctObservation& obs, int k, const LandmarkBasis& basis,
                                const IctFitOptions& options) {
  const std::string where = "ict fit: photo " + std::to_string(k) + ": ";
  if (Status s = obs.intrinsics.Validate(); !s.ok())
    return Status::Error(where + "intrinsics: " + s.message());
  if (obs.landmarks.size() != kNumLandmarks)
    return Status::Error(where + std::to_string(obs.landmarks.size()) + " landmarks, expected 68");
  if (!obs.weights.empty() && obs.weights.size() != kNumLandmarks)
    return Status::Error(where + std::to_string(obs.weights.size()) + " weights, expected 68 or none");
  PhotoData d;
  d.intrinsics = obs.intrinsics;
  int used = 0;
  for (int i = 0; i < kNumLandmarks; ++i) {
    const double w = obs.weights.empty() ? 1.0 : obs.weights[i];
    const std::string which = "landmark " + std::to_string(i) + " ";
    if (!std::isfinite(w) || w < 0)
      return Status::Error(where + which + "has weight " + std::to_string(w) + " (must be finite, >= 0)");
    if (w > 0 && !obs.landmarks[i].allFinite())
      return Status::Error(where + which + "is not finite (give it weight 0 if it is missing)");
    d.observed[i] = obs.landmarks[i].cast<double>();
    d.weight[i] = basis.present[i] ? w * (i <= 16 ? options.jaw_line_weight : 1.0) : 0.0;
    used += d.weight[i] > 0;
  }
  if (used == 0) return Status::Error(where + "every landmark is missing (weight 0)");
  if (used < kMinLandmarks)
    return Status::Error(where + "only " + std::to_string(used) + " landmarks of weight > 0; at least " +
                         std::to_string(kMinLandmarks) + " are needed");
  int right = 0, left = 0;
  const Vec2d eyes = EyeCentre(d, 42, &left) - EyeCentre(d, 36, &right);
  d.iod_px = left > 0 && right > 0 ? eyes.norm() : 0.0;
  if (left > 0 && right > 0 && !(d.iod_px > 1e-6))
    return Status::Error(where + "the eyes' landmarks coincide (inter-ocular distance 0)");
  return d;
}

// The normalised image-plane point of a pixel: the camera-frame direction (x, y, -1) through it.
Vec2d Normalised(const Intrinsics& k, const Vec2d& uv) {
  return Vec2d((uv.x() - k.cx) / k.fl_x, -(uv.y() - k.cy) / k.fl_y);
}

// The start of the rigid solve: the mean head upright, turned by the eye line's roll, at the depth
// where its landmarks' spread matches the observed one, centred on them. Completes d->iod_px when
// an eye has no landmarks.
void InitialPose(const LandmarkBasis& b, PhotoData* d, const PhotoParams& p) {
  Vec3d model_mean = Vec3d::Zero();
  Vec2d obs_mean = Vec2d::Zero();
  std::vector<std::pair<Vec3d, Vec2d>> used;
  for (int i = 0; i < kNumLandmarks; ++i) {
    if (d->weight[i] == 0) continue;
    used.emplace_back(b.neutral.segment<3>(3 * i), Normalised(d->intrinsics, d->observed[i]));
    model_mean += used.back().first;
    obs_mean += used.back().second;
  }
  model_mean /= static_cast<double>(used.size());
  obs_mean /= static_cast<double>(used.size());
  double model_spread = 0, obs_spread = 0;
  for (const auto& [m, q] : used) {
    model_spread += (m - model_mean).head<2>().squaredNorm();
    obs_spread += (q - obs_mean).squaredNorm();
  }
  const double depth = std::sqrt(model_spread / std::max(obs_spread, 1e-30));
  double roll = 0;
  int left = 0, right = 0;
  const Vec2d left_eye = EyeCentre(*d, 42, &left), right_eye = EyeCentre(*d, 36, &right);
  if (left > 0 && right > 0) {  // the head's +x (subject's left) runs from the right eye to the left
    const Vec2d e = Normalised(d->intrinsics, left_eye) - Normalised(d->intrinsics, right_eye);
    roll = std::atan2(e.y(), e.x());
  }
  p.rotation[0] = p.rotation[1] = 0;
  p.rotation[2] = roll;
  const Vec3d t = depth * Vec3d(obs_mean.x(), obs_mean.y(), -1) - RotationOf(p.rotation) * model_mean;
  std::copy_n(t.data(), 3, p.translation);
  if (d->iod_px == 0) {
    Vec3d model_eyes = Vec3d::Zero();  // left eye centre - right eye centre, x 6
    for (int i = 0; i < 6; ++i)
      model_eyes += b.neutral.segment<3>(3 * (42 + i)) - b.neutral.segment<3>(3 * (36 + i));
    d->iod_px = std::abs(d->intrinsics.fl_x) * model_eyes.norm() / 6 / depth;
  }
}

// The fitted photo: pose, clamped weights, projections and landmark errors.
IctPhotoFit Report(const LandmarkBasis& b, const PhotoData& d, const PhotoParams& p, const double* identity) {
  IctPhotoFit f;
  const Mat3d r = RotationOf(p.rotation);
  const Vec3d t(p.translation[0], p.translation[1], p.translation[2]);
  f.cam_from_head.block<3, 3>(0, 0) = r;
  f.cam_from_head.block<3, 1>(0, 3) = t;
  for (int e = 0; e < b.num_expressions(); ++e)
    f.expression.push_back(static_cast<float>(std::clamp(p.expression[e], 0.0, 1.0)));
  f.iod_px = d.iod_px;
  const VecXd x = b.Positions(identity, p.expression);
  double sum2 = 0;
  for (int i = 0; i < kNumLandmarks; ++i) {
    const Vec3d cam = r * x.segment<3>(3 * i) + t;
    const bool visible = b.present[i] && cam.z() < -kMinDepth;
    const Vec2d uv = visible ? ProjectCam(d.intrinsics, cam, nullptr) : Vec2d::Constant(NAN);
    f.projected.push_back(uv.cast<float>());
    if (d.weight[i] == 0) continue;
    const double e =
        visible ? (uv - d.observed[i]).norm() / d.iod_px : std::numeric_limits<double>::infinity();
    sum2 += e * e;
    f.max_iod = std::max(f.max_iod, e);
    ++f.landmarks_used;
  }
  f.rms_iod = std::sqrt(sum2 / std::max(f.landmarks_used, 1));
  return f;
}

// With known cameras: each photo's rigid cam_from_world and the shared head pose (angle-axis [3],
// translation [3], log scale [1]) the landmark residuals use instead of the photo's own pose.
struct SharedPose {
  const std::vector<Mat4d>* cam_from_world;
  double* pose;
};

// The Ceres problem over the unknowns (it points into them, and into shared->pose).
void BuildProblem(const LandmarkBasis& b, const std::vector<PhotoData>& data, const IctFitOptions& o,
                  Unknowns* u, ceres::Problem* problem, const SharedPose* shared = nullptr) {
  double* identity = u->identity();
  problem->AddResidualBlock(new GaussianPrior(b.num_identity(), o.identity_prior_sigma), nullptr, identity);
  for (size_t k = 0; k < data.size(); ++k) {
    const PhotoParams p = u->photo(static_cast<int>(k));
    if (shared == nullptr) {
      problem->AddResidualBlock(new LandmarkCost(&b, &data[k], o.landmark_sigma_iod), nullptr, identity,
                                p.expression, p.rotation, p.translation);
    } else {
      problem->AddResidualBlock(
          new LandmarkCost(&b, &data[k], o.landmark_sigma_iod, (*shared->cam_from_world)[k]), nullptr,
          identity, p.expression, shared->pose, shared->pose + 3, shared->pose + 6);
    }
    problem->AddResidualBlock(new ExpressionPrior(&b, o), nullptr, p.expression);
    for (int e = 0; e < b.num_expressions(); ++e) {
      problem->SetParameterLowerBound(p.expression, e, 0.0);
      problem->SetParameterUpperBound(p.expression, e, 1.0);
    }
  }
}

// Holds (or frees) the identity and every expression block: the rigid stage holds them.
void SetShapeConstant(Unknowns* u, bool constant, ceres::Problem* problem) {
  const auto set = [&](double* block) {
    constant ? problem->SetParameterBlockConstant(block) : problem->SetParameterBlockVariable(block);
  };
  set(u->identity());
  for (int k = 0; k < u->num_photos(); ++k) set(u->photo(k).expression);
}

// One Levenberg-Marquardt solve whose Schur complement eliminates the blocks `eliminate` (no two
// in one residual); an explicit ordering, as Ceres' automatic one may vary from run to run.
Status RunSolver(ceres::Problem& problem, int max_iterations, const IctFitOptions& o,
                 const std::vector<double*>& eliminate, ceres::Solver::Summary* summary) {
  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  so.linear_solver_type = eliminate.empty() ? ceres::DENSE_QR : ceres::DENSE_SCHUR;
  so.max_num_iterations = max_iterations;
  so.function_tolerance = o.function_tolerance;
  so.check_gradients = o.check_gradients;
  // Entries of ~1e-9 (landmarks a blendshape hardly moves) differ from central differences by
  // ~3e-13 absolute, up to ~2e-4 relative; a wrong derivative is off by its own size.
  so.gradient_check_relative_precision = 1e-3;
  so.parameter_tolerance = 1e-10;
  so.gradient_tolerance = 1e-14;
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  std::vector<double*> blocks;
  problem.GetParameterBlocks(&blocks);
  for (double* block : blocks) ordering->AddElementToGroup(block, 1);
  for (double* block : eliminate) ordering->AddElementToGroup(block, 0);
  if (!eliminate.empty()) so.linear_solver_ordering = ordering;
  so.num_threads = 1;  // deterministic
  so.logging_type = ceres::SILENT;
  ceres::Solve(so, &problem, summary);
  if (!summary->IsSolutionUsable()) return Status::Error("ict fit: the solver failed: " + summary->message);
  return Status::Ok();
}

// The shared head pose (world_from_head: angle-axis, translation, log scale) that agrees best with
// per-photo poses cam_from_head (cm) and the known cameras: the head's origin seen from camera k lies
// at c_k + s d_k (c_k the camera's centre, d_k its cm offset turned into the world, s world units per
// cm), so s is the least-squares scale that makes those points coincide; the rotation is the
// projection onto SO(3) of the mean of the photos' head-to-world rotations.
Status InitialSharedPose(const std::vector<Mat4d>& cam_from_world, const std::vector<Mat4d>& cam_from_head,
                         double* pose) {
  const size_t n = cam_from_world.size();
  std::vector<Vec3d> c(n), d(n);
  Vec3d c_mean = Vec3d::Zero(), d_mean = Vec3d::Zero();
  Mat3d rotation_sum = Mat3d::Zero();
  for (size_t k = 0; k < n; ++k) {
    const Mat3d rc = cam_from_world[k].block<3, 3>(0, 0);
    c[k] = -rc.transpose() * cam_from_world[k].block<3, 1>(0, 3);
    d[k] = rc.transpose() * cam_from_head[k].block<3, 1>(0, 3);
    c_mean += c[k] / static_cast<double>(n);
    d_mean += d[k] / static_cast<double>(n);
    rotation_sum += rc.transpose() * cam_from_head[k].block<3, 3>(0, 0);
  }
  double num = 0, den = 0;
  for (size_t k = 0; k < n; ++k) {
    num -= (c[k] - c_mean).dot(d[k] - d_mean);
    den += (d[k] - d_mean).squaredNorm();
  }
  // The offsets must differ by a real fraction of their length: else the views do not tell the
  // scale (one photo, or cameras on one line through the head).
  if (!(den > 1e-4 * d_mean.squaredNorm() * static_cast<double>(n)) || !(num / den > 0))
    return Status::Error(
        "ict fit: the known cameras do not determine the head's scale (they must see it from at least two "
        "places not on one line with it)");
  const double scale = num / den;
  const Eigen::JacobiSVD<Mat3d> svd(rotation_sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3d u = svd.matrixU();
  if ((u * svd.matrixV().transpose()).determinant() < 0) u.col(2) *= -1;
  const Mat3d r = u * svd.matrixV().transpose();
  ceres::RotationMatrixToAngleAxis(r.data(), pose);
  const Vec3d t = c_mean + scale * d_mean;
  std::copy_n(t.data(), 3, pose + 3);
  pose[6] = std::log(scale);
  return Status::Ok();
}

// A photo's cam_from_head (rigid, cm) from its known camera and the shared world_from_head pose,
// written as PhotoParams' angle-axis and translation.
void PhotoPoseFromShared(const Mat4d& cam_from_world, const double* pose, const PhotoParams& p) {
  const Mat3d rc = cam_from_world.block<3, 3>(0, 0);
  const double scale = std::exp(pose[6]);
  const Mat3d r = rc * RotationOf(pose);
  const Vec3d t = (rc * Vec3d(pose[3], pose[4], pose[5]) + cam_from_world.block<3, 1>(0, 3)) / scale;
  ceres::RotationMatrixToAngleAxis(r.data(), p.rotation);
  std::copy_n(t.data(), 3, p.translation);
}

// The known-camera solve: the shared pose started from the per-photo poses in u (a rigid solve of
// their own), then solved alone, then with everything but the cameras. Leaves each photo's pose in
// u as its camera composed with the shared pose, and fit->head_from_world.
Status SolveKnownCameras(const LandmarkBasis& b, const std::vector<PhotoData>& data,
                         const std::vector<Mat4d>& cam_from_world, const IctFitOptions& o, Unknowns* u,
                         IctFit* fit) {
  const int n = static_cast<int>(data.size());
  std::vector<Mat4d> cam_from_head(n, Mat4d::Identity());
  for (int k = 0; k < n; ++k) {
    const PhotoParams p = u->photo(k);
    cam_from_head[k].block<3, 3>(0, 0) = RotationOf(p.rotation);
    cam_from_head[k].block<3, 1>(0, 3) = Vec3d(p.translation[0], p.translation[1], p.translation[2]);
  }
  std::array<double, 7> pose{};  // angle-axis, translation, log scale
  ICEF_RETURN_IF_ERROR(InitialSharedPose(cam_from_world, cam_from_head, pose.data()));
  ceres::Problem problem;
  const SharedPose shared{&cam_from_world, pose.data()};
  BuildProblem(b, data, o, u, &problem, &shared);
  std::vector<double*> expressions;
  for (int k = 0; k < n; ++k) expressions.push_back(u->photo(k).expression);
  ceres::Solver::Summary summary;
  SetShapeConstant(u, true, &problem);
  ICEF_RETURN_IF_ERROR(RunSolver(problem, std::max(o.rigid_iterations, 30), o, {}, &summary));
  fit->iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
  SetShapeConstant(u, false, &problem);
  ICEF_RETURN_IF_ERROR(RunSolver(problem, o.max_iterations, o, expressions, &summary));
  fit->iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
  fit->final_cost = summary.final_cost;
  for (int k = 0; k < n; ++k) PhotoPoseFromShared(cam_from_world[k], pose.data(), u->photo(k));
  // head_from_world, the inverse of world_from_head: x_head = R^T (x_world - t) / s.
  const double scale = std::exp(pose[6]);
  Similarity head_from_world;
  head_from_world.scale = 1.0 / scale;
  head_from_world.rotation = RotationOf(pose.data()).transpose();
  head_from_world.translation = -(head_from_world.rotation * Vec3d(pose[3], pose[4], pose[5])) / scale;
  fit->head_from_world = head_from_world;
  return Status::Ok();
}

}  // namespace

Status IctFitOptions::Validate() const {
  const auto positive = [](double v) { return v > 0 && std::isfinite(v); };
  if (num_identity < 1) return Status::Error("num_identity must be >= 1");
  if (!positive(landmark_sigma_iod)) return Status::Error("landmark_sigma_iod must be a finite number > 0");
  if (!(jaw_line_weight >= 0 && jaw_line_weight <= 1))
    return Status::Error("jaw_line_weight must be in [0, 1]");
  if (!positive(identity_prior_sigma))
    return Status::Error("identity_prior_sigma must be a finite number > 0");
  if (!positive(expression_prior_sigma))
    return Status::Error("expression_prior_sigma must be a finite number > 0");
  if (!(expression_prior_laplace >= 0 && std::isfinite(expression_prior_laplace)))
    return Status::Error("expression_prior_laplace must be a finite number >= 0");
  if (!(symmetry_sigma > 0)) return Status::Error("symmetry_sigma must be > 0 (infinity: no coupling)");
  if (rigid_iterations < 0) return Status::Error("rigid_iterations must be >= 0");
  if (max_iterations < 1) return Status::Error("max_iterations must be >= 1");
  if (!(function_tolerance > 0 && function_tolerance < 1))
    return Status::Error("function_tolerance must be in (0, 1)");
  return Status::Ok();
}

std::string IctFitOptions::ToString() const {
  std::ostringstream os;
  os << "IctFitOptions(num_identity=" << num_identity << ", landmark_sigma_iod=" << landmark_sigma_iod
     << ", jaw_line_weight=" << jaw_line_weight << ", identity_prior_sigma=" << identity_prior_sigma
     << ", expression_prior_sigma=" << expression_prior_sigma
     << ", expression_prior_laplace=" << expression_prior_laplace << ", symmetry_sigma=" << symmetry_sigma
     << ", rigid_iterations=" << rigid_iterations << ", max_iterations=" << max_iterations
     << ", function_tolerance=" << function_tolerance << ", check_gradients=" << check_gradients << ")";
  return os.str();
}

IctFitOptions IctFitOptions::ForPhotos() {
  IctFitOptions o;
  o.num_identity = 100;
  o.identity_prior_sigma = 3;
  o.expression_prior_laplace = 0.2;
  return o;
}

std::string IctPhotoFit::ToString() const {
  std::ostringstream os;
  os.precision(4);
  const Eigen::AngleAxisd aa(Mat3d(cam_from_head.block<3, 3>(0, 0)));
  os << "IctPhotoFit(rotation=" << aa.angle() * 180 / M_PI << " deg, translation=[" << cam_from_head(0, 3)
     << ", " << cam_from_head(1, 3) << ", " << cam_from_head(2, 3) << "] cm, rms_iod=" << rms_iod
     << ", max_iod=" << max_iod << ", landmarks_used=" << landmarks_used << ", iod_px=" << iod_px << ")";
  return os.str();
}

std::string IctFit::BriefReport() const {
  std::ostringstream os;
  os.precision(3);
  os << "ict fit: " << photos.size() << " photos, " << identity.size() << " identity modes, landmark RMS "
     << rms_iod << " IOD (max " << max_iod << "), " << iterations << " iterations, cost " << final_cost;
  return os.str();
}

std::string IctFit::ToString() const {
  std::string s = BriefReport();
  for (size_t k = 0; k < photos.size(); ++k)
    s += "\n  photo " + std::to_string(k) + ": " + photos[k].ToString();
  return s;
}

Result<IctFit> FitIctToLandmarks(const face::IctModel& model, const std::vector<IctObservation>& photos,
                                 const IctFitOptions& options) {
  ICEF_RETURN_IF_ERROR(options.Validate().WithContext("ict fit options"));
  if (photos.empty()) return Status::Error("ict fit: no observations");
  if (options.num_identity > model.num_identities())
    return Status::Error("ict fit options: num_identity " + std::to_string(options.num_identity) +
                         " exceeds the model's " + std::to_string(model.num_identities()) + " modes");
  const LandmarkBasis basis = MakeBasis(model, options.num_identity);
  std::vector<PhotoData> data;
  for (size_t k = 0; k < photos.size(); ++k) {
    ICEF_ASSIGN_OR_RETURN(PhotoData d, MakePhotoData(photos[k], static_cast<int>(k), basis, options));
    data.push_back(std::move(d));
  }
  const int n = static_cast<int>(photos.size());
  const auto known = [](const IctObservation& o) { return o.cam_from_world.has_value(); };
  const bool known_cameras = std::all_of(photos.begin(), photos.end(), known);
  if (!known_cameras && std::any_of(photos.begin(), photos.end(), known))
    return Status::Error("ict fit: some photos have a known camera and some do not (all or none)");
  std::vector<Mat4d> cam_from_world;
  for (int k = 0; known_cameras && k < n; ++k) {
    const Mat4d& m = *photos[k].cam_from_world;
    const Mat3d r = m.block<3, 3>(0, 0);
    if (!m.allFinite() || !(r.transpose() * r).isApprox(Mat3d::Identity(), 1e-6) || !(r.determinant() > 0))
      return Status::Error("ict fit: photo " + std::to_string(k) +
                           ": cam_from_world is not a rigid transform");
    cam_from_world.push_back(m);
  }
  Unknowns u(basis.num_identity(), basis.num_expressions(), n);
  for (int k = 0; k < n; ++k) InitialPose(basis, &data[k], u.photo(k));
  ceres::Problem problem;
  BuildProblem(basis, data, options, &u, &problem);
  IctFit fit;
  ceres::Solver::Summary summary;
  std::vector<double*> rotations, expressions;  // the blocks each stage eliminates
  for (int k = 0; k < n; ++k) rotations.push_back(u.photo(k).rotation);
  for (int k = 0; k < n; ++k) expressions.push_back(u.photo(k).expression);
  // The poses of the mean neutral head first (with known cameras, they start the shared pose).
  const int rigid_iterations =
      known_cameras ? std::max(options.rigid_iterations, 30) : options.rigid_iterations;
  if (rigid_iterations > 0) {
    SetShapeConstant(&u, true, &problem);
    ICEF_RETURN_IF_ERROR(RunSolver(problem, rigid_iterations, options, rotations, &summary));
    fit.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
    SetShapeConstant(&u, false, &problem);
  }
  if (known_cameras) {
    ICEF_RETURN_IF_ERROR(SolveKnownCameras(basis, data, cam_from_world, options, &u, &fit));
  } else {
    ICEF_RETURN_IF_ERROR(RunSolver(problem, options.max_iterations, options, expressions, &summary));
    fit.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
    fit.final_cost = summary.final_cost;
  }

  fit.identity.assign(u.identity(), u.identity() + basis.num_identity());
  double sum2 = 0;
  int used = 0;
  for (int k = 0; k < n; ++k) {
    fit.photos.push_back(Report(basis, data[k], u.photo(k), u.identity()));
    const IctPhotoFit& f = fit.photos.back();
    sum2 += f.rms_iod * f.rms_iod * f.landmarks_used;
    used += f.landmarks_used;
    fit.max_iod = std::max(fit.max_iod, f.max_iod);
  }
  fit.rms_iod = std::sqrt(sum2 / std::max(used, 1));
  return fit;
}

}  // namespace icef::face
