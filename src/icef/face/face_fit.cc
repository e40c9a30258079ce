#include "icef/face/face_fit.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "icef/face/expression.h"
#include "icef/face/face_model.h"

namespace icef::face {

namespace {

constexpr int kNumLandmarks = 68;
constexpr int kPoseSize =
    7;  // angle-axis [3] (on top of the initial rotation), translation [3], log scale [1]

Vec3d EyeCentre(std::span<const Vec3f> lm, int first) {
  Vec3d c = Vec3d::Zero();
  for (int i = first; i < first + 6; ++i) c += lm[i].cast<double>();
  return c / 6.0;
}

double InterOcular2d(const std::vector<Vec2f>& lm) {
  Vec2d a = Vec2d::Zero(), b = Vec2d::Zero();
  for (int i = 0; i < 6; ++i) a += lm[36 + i].cast<double>(), b += lm[42 + i].cast<double>();
  return (a - b).norm() / 6.0;
}

// The style's parameter block: the gains as they are, then each offset + 1 (so that Ceres' relative
// numeric-difference step, 1e-3 of the value, is about 1e-3 head units for an offset near 0 too).
using StyleBlock = std::array<double, ExpressionStyle::kNumFields>;

StyleBlock StyleToBlock(const ExpressionStyle& style) {
  StyleBlock b;
  const auto fields = style.Fields();
  for (int i = 0; i < ExpressionStyle::kNumFields; ++i)
    b[i] = fields[i].second + (i < ExpressionStyle::kNumGains ? 0.0 : 1.0);
  return b;
}

ExpressionStyle StyleFromBlock(const double* block) {
  ExpressionStyle style;
  const auto fields = style.Fields();
  for (int i = 0; i < ExpressionStyle::kNumFields; ++i)
    style.SetField(fields[i].first,
                   static_cast<float>(block[i] - (i < ExpressionStyle::kNumGains ? 0.0 : 1.0)));
  return style;
}

// The face model's landmarks of every frame (head frame) for one shape and style, rebuilt only when
// they change (Ceres perturbs one parameter block at a time, so the pose's derivatives reuse it).
class LandmarkCache {
 public:
  explicit LandmarkCache(std::span<const FitFrame> frames) : frames_(frames) {}
  const std::vector<std::array<Vec3f, 68>>& For(const double* shape, const double* style) {
    Key key;
    for (int i = 0; i < ShapeParams::kCount; ++i) key[i] = static_cast<float>(shape[i]);
    for (int i = 0; i < ExpressionStyle::kNumFields; ++i)
      key[ShapeParams::kCount + i] = static_cast<float>(style[i]);
    if (!valid_ || key != key_) {
      std::array<float, ShapeParams::kCount> values;
      std::copy_n(key.begin(), ShapeParams::kCount, values.begin());
      const FaceModel model(ShapeParams::FromArray(values), StyleFromBlock(style));
      landmarks_.clear();
      for (const FitFrame& f : frames_) landmarks_.push_back(model.Landmarks(model.Prepare(f.expression)));
      key_ = key;
      valid_ = true;
    }
    return landmarks_;
  }

 private:
  using Key = std::array<float, ShapeParams::kCount + ExpressionStyle::kNumFields>;
  std::span<const FitFrame> frames_;
  Key key_{};
  bool valid_ = false;
  std::vector<std::array<Vec3f, 68>> landmarks_;
};

Similarity PoseToSimilarity(const double* pose, const Similarity& base) {
  double r[9];
  ceres::AngleAxisToRotationMatrix(pose, r);  // column major
  Mat3d delta;
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) delta(row, c) = r[3 * c + row];
  Similarity s;
  s.rotation = delta * base.rotation;
  s.translation = Vec3d(pose[3], pose[4], pose[5]);
  s.scale = base.scale * std::exp(pose[6]);
  return s;
}

// Per-landmark errors in IOD of a shape + pose: [frame][landmark] (nullopt-free: behind-camera
// projections count as a large error).
struct Problem {
  std::span<const FitFrame> frames;
  Similarity base;
  double iod_head = 1.0;                    // the average head's inter-ocular distance (head units)
  std::vector<double> iod_px;               // per 2D frame
  std::vector<std::vector<double>> weight;  // [frame][landmark] 0 or 1
  mutable LandmarkCache cache;
  int num_residuals = 0;

  Problem(std::span<const FitFrame> f, const Similarity& b, double iod)
      : frames(f), base(b), iod_head(iod), cache(f) {
    for (const FitFrame& fr : frames) {
      iod_px.push_back(fr.landmarks_3d ? 0.0 : InterOcular2d(*fr.landmarks_2d));
      weight.emplace_back(kNumLandmarks, 1.0);
      num_residuals += kNumLandmarks * (fr.landmarks_3d ? 3 : 2);
    }
  }

  // Residual vector (IOD units, unweighted by sigma), weighted by the inlier mask.
  void Residuals(const double* shape, const double* style, const double* pose, double* out) const {
    const std::vector<std::array<Vec3f, 68>>& model = cache.For(shape, style);
    const Similarity s = PoseToSimilarity(pose, base);
    int r = 0;
    for (size_t k = 0; k < frames.size(); ++k) {
      const FitFrame& f = frames[k];
      for (int i = 0; i < kNumLandmarks; ++i) {
        const double w = weight[k][i];
        if (f.landmarks_3d) {
          const Vec3d d =
              (s.Apply((*f.landmarks_3d)[i].cast<double>()) - model[k][i].cast<double>()) / iod_head;
          for (int a = 0; a < 3; ++a) out[r++] = w * d[a];
        } else {
          const auto proj = f.camera->Project(s.ApplyInverse(model[k][i].cast<double>()));
          Vec2d d(1.0, 1.0);  // behind the camera: a large, constant error
          if (proj) d = (proj->uv - (*f.landmarks_2d)[i].cast<double>()) / iod_px[k];
          for (int a = 0; a < 2; ++a) out[r++] = w * d[a];
        }
      }
    }
  }

  // Per-landmark error norms [frame][landmark] in IOD (ignoring the weights).
  std::vector<std::vector<double>> Errors(const double* shape, const double* style,
                                          const double* pose) const {
    std::vector<std::vector<double>> saved = weight;
    auto* self = const_cast<Problem*>(this);
    for (auto& row : self->weight) std::fill(row.begin(), row.end(), 1.0);
    std::vector<double> res(num_residuals);
    Residuals(shape, style, pose, res.data());
    self->weight = saved;
    std::vector<std::vector<double>> e;
    int r = 0;
    for (const FitFrame& f : frames) {
      const int dim = f.landmarks_3d ? 3 : 2;
      std::vector<double> row(kNumLandmarks);
      for (int i = 0; i < kNumLandmarks; ++i, r += dim) {
        double s = 0;
        for (int a = 0; a < dim; ++a) s += res[r + a] * res[r + a];
        row[i] = std::sqrt(s);
      }
      e.push_back(std::move(row));
    }
    return e;
  }
};

struct LandmarkCost {
  const Problem* problem;
  double inv_sigma;
  bool operator()(double const* const* params, double* residuals) const {
    problem->Residuals(params[0], params[1], params[2], residuals);
    for (int i = 0; i < problem->num_residuals; ++i) residuals[i] *= inv_sigma;
    return true;
  }
};

struct ShapePriorCost {
  double inv_sigma;
  template <typename T>
  bool operator()(const T* shape, T* residuals) const {
    for (int i = 0; i < ShapeParams::kCount; ++i) residuals[i] = (shape[i] - T(1.0)) * T(inv_sigma);
    return true;
  }
};

// The style's prior: each gain's log and each offset around the generic style's 1 and 0.
struct StylePriorCost {
  double inv_sigma_gain, inv_sigma_offset;
  template <typename T>
  bool operator()(const T* style, T* residuals) const {
    for (int i = 0; i < ExpressionStyle::kNumFields; ++i)
      residuals[i] = i < ExpressionStyle::kNumGains ? log(style[i]) * T(inv_sigma_gain)
                                                    : (style[i] - T(1.0)) * T(inv_sigma_offset);
    return true;
  }
};

// Landmark noise assumed by the prior's balance (IOD units): a shape scale 1 sigma off the average
// costs as much as one landmark off by this much.
constexpr double kLandmarkSigma = 0.02;

// Initial similarity: Umeyama between the observed 3D landmarks and the average head's; from 2D
// only, the head is placed where the nose rays of the cameras meet, facing them, sized by the IOD.
Result<Similarity> InitialSimilarity(std::span<const FitFrame> frames, double iod_head) {
  const FaceModel average(ShapeParams::Average());
  std::vector<Vec3d> src, dst;
  for (const FitFrame& f : frames) {
    if (!f.landmarks_3d) continue;
    const std::array<Vec3f, 68> m = average.Landmarks(average.Prepare(f.expression));
    for (int i = 0; i < kNumLandmarks; ++i)
      src.push_back((*f.landmarks_3d)[i].cast<double>()), dst.push_back(m[i].cast<double>());
  }
  Similarity s;
  if (!src.empty()) {
    Eigen::Matrix3Xd a(3, src.size()), b(3, dst.size());
    for (size_t i = 0; i < src.size(); ++i) a.col(i) = src[i], b.col(i) = dst[i];
    const Eigen::Matrix4d t = Eigen::umeyama(a, b, true);
    s.scale = t.block<3, 1>(0, 0).norm();
    if (!(s.scale > 0) || !std::isfinite(s.scale)) return Status::Error("face fit: degenerate 3D landmarks");
    s.rotation = t.block<3, 3>(0, 0) / s.scale;
    s.translation = t.block<3, 1>(0, 3);
    return s;
  }
  // 2D: least-squares meeting point of the rays through the nose tip (landmark 30).
  Mat3d lhs = Mat3d::Zero();
  Vec3d rhs = Vec3d::Zero(), toward = Vec3d::Zero(), up = Vec3d::Zero();
  double world_iod = 0;
  for (const FitFrame& f : frames) {
    const Ray ray = f.camera->RayThrough((*f.landmarks_2d)[30].x(), (*f.landmarks_2d)[30].y());
    const Vec3d o = ray.origin.cast<double>(), d = ray.direction.cast<double>().normalized();
    const Mat3d p = Mat3d::Identity() - d * d.transpose();
    lhs += p;
    rhs += p * o;
    toward -= d;
    up += f.camera->world_from_cam().block<3, 1>(0, 1);
  }
  Vec3d nose_world;
  if (frames.size() >= 2 && std::abs(lhs.determinant()) > 1e-9) {
    nose_world = lhs.ldlt().solve(rhs);
  } else {  // one view: the depth at which the average head's IOD matches the observed one
    const FitFrame& f = frames[0];
    const Ray ray = f.camera->RayThrough((*f.landmarks_2d)[30].x(), (*f.landmarks_2d)[30].y());
    // |fl_x|: a mirrored camera has fl_x < 0 (math/camera.h).
    const double depth = std::abs(f.camera->intrinsics().fl_x) * iod_head / InterOcular2d(*f.landmarks_2d);
    nose_world = ray.origin.cast<double>() + depth * ray.direction.cast<double>().normalized();
  }
  for (const FitFrame& f : frames) {
    const auto proj = f.camera->Project(nose_world);
    if (!proj) return Status::Error("face fit: the landmarks' meeting point lies behind a camera");
    world_iod += InterOcular2d(*f.landmarks_2d) * proj->depth / std::abs(f.camera->intrinsics().fl_x);
  }
  world_iod /= double(frames.size());
  const Vec3d z = toward.normalized();
  const Vec3d x = up.cross(z).normalized();
  const Vec3d y = z.cross(x);
  s.rotation.row(0) = x.transpose();
  s.rotation.row(1) = y.transpose();
  s.rotation.row(2) = z.transpose();
  s.scale = iod_head / world_iod;
  s.translation = average.NeutralLandmarks()[30].cast<double>() - s.scale * (s.rotation * nose_world);
  return s;
}

Status CheckFrames(std::span<const FitFrame> frames) {
  if (frames.empty()) return Status::Error("face fit: no frames");
  for (size_t k = 0; k < frames.size(); ++k) {
    const FitFrame& f = frames[k];
    const std::string where = "face fit: frame " + std::to_string(k) + ": ";
    if (Status s = ValidateExpression(f.expression); !s.ok()) return Status::Error(where + s.message());
    if (f.landmarks_3d) {
      if (f.landmarks_3d->size() != kNumLandmarks)
        return Status::Error(where + "landmarks_3d must have 68 points");
      for (const Vec3f& p : *f.landmarks_3d)
        if (!p.allFinite()) return Status::Error(where + "landmarks_3d has a non-finite value");
    } else if (f.landmarks_2d) {
      if (f.landmarks_2d->size() != kNumLandmarks)
        return Status::Error(where + "landmarks_2d must have 68 points");
      if (!f.camera) return Status::Error(where + "landmarks_2d need the frame's camera");
      for (const Vec2f& p : *f.landmarks_2d)
        if (!p.allFinite()) return Status::Error(where + "landmarks_2d has a non-finite value");
      if (!(InterOcular2d(*f.landmarks_2d) > 0))
        return Status::Error(where + "landmarks_2d: the eyes coincide");
    } else {
      return Status::Error(where + "no landmarks (landmarks_3d or landmarks_2d)");
    }
  }
  return Status::Ok();
}

}  // namespace

std::string Similarity::ToString() const {
  std::ostringstream os;
  const Eigen::AngleAxisd aa(rotation);
  os << "Similarity(scale=" << scale << ", rotation=" << aa.angle() * 180.0 / M_PI << " deg about ["
     << aa.axis().transpose() << "], translation=[" << translation.transpose() << "])";
  return os.str();
}

Status FaceFitOptions::Validate() const {
  if (!(shape_prior_sigma > 0) || !std::isfinite(shape_prior_sigma))
    return Status::Error("shape_prior_sigma must be a finite number > 0");
  if (max_iterations < 1) return Status::Error("max_iterations must be >= 1");
  if (!(outlier_iod > 0)) return Status::Error("outlier_iod must be > 0");
  if (!(style_gain_sigma > 0) || !std::isfinite(style_gain_sigma))
    return Status::Error("style_gain_sigma must be a finite number > 0");
  if (!(style_offset_sigma > 0) || !std::isfinite(style_offset_sigma))
    return Status::Error("style_offset_sigma must be a finite number > 0");
  if (!(style_min_f >= 0) || !std::isfinite(style_min_f))
    return Status::Error("style_min_f must be a finite number >= 0");
  return Status::Ok();
}

std::string FaceFitOptions::ToString() const {
  std::ostringstream os;
  os << "FaceFitOptions(shape_prior_sigma=" << shape_prior_sigma << ", fit_shape=" << fit_shape
     << ", max_iterations=" << max_iterations << ", outlier_iod=" << outlier_iod
     << ", fit_style=" << fit_style << ", style_gain_sigma=" << style_gain_sigma
     << ", style_offset_sigma=" << style_offset_sigma << ", style_min_f=" << style_min_f << ")";
  return os.str();
}

std::string FaceFit::BriefReport() const {
  std::ostringstream os;
  os.precision(3);
  os << "face fit: landmark RMS " << rms_iod << " IOD (max " << max_iod << "), " << landmarks_used << "/"
     << landmarks_total << " landmarks, " << iterations << " iterations, head scale "
     << head_from_world.scale;
  if (style_rejected) {
    os << "; expression style: generic (a fitted one explained the landmarks no better than noise: F "
       << style_f << ")";
  } else if (!style.IsGeneric()) {  // the fields the fit moved off the generic style
    os << "; expression style:";
    const auto generic = ExpressionStyle::Generic().Fields();
    const auto fields = style.Fields();
    int shown = 0;
    for (size_t i = 0; i < fields.size(); ++i)
      if (std::abs(fields[i].second - generic[i].second) >= 0.005f)
        os << (shown++ ? ", " : " ") << fields[i].first << " " << fields[i].second;
    if (shown == 0) os << " generic within 0.005";
    os << " (landmark RMS " << generic_style_rms_iod << " IOD in the generic style, F " << style_f << ")";
  }
  return os.str();
}

double InterOcularDistance(std::span<const Vec3f> landmarks) {
  ICEF_CHECK(landmarks.size() == kNumLandmarks, "InterOcularDistance needs 68 landmarks");
  return (EyeCentre(landmarks, 36) - EyeCentre(landmarks, 42)).norm();
}

namespace {

// One fit, with the style fitted or held generic as options.fit_style says.
Result<FaceFit> FitOnce(std::span<const FitFrame> frames, const FaceFitOptions& options) {
  const FaceModel average(ShapeParams::Average());
  const double iod_head = InterOcularDistance(average.NeutralLandmarks());
  ICEF_ASSIGN_OR_RETURN(const Similarity base, InitialSimilarity(frames, iod_head));

  Problem problem(frames, base, iod_head);
  std::array<double, ShapeParams::kCount> shape;
  shape.fill(1.0);
  std::array<double, kPoseSize> pose = {
      0, 0, 0, base.translation.x(), base.translation.y(), base.translation.z(), 0};
  StyleBlock style = StyleToBlock(ExpressionStyle::Generic());

  FaceFit fit;
  fit.landmarks_total = kNumLandmarks * static_cast<int>(frames.size());
  for (int pass = 0; pass < 2; ++pass) {
    ceres::Problem cp;
    ceres::NumericDiffOptions nd;
    nd.relative_step_size = 1e-3;  // the landmarks come from a float SDF: steps well above its noise
    auto* cost = new ceres::DynamicNumericDiffCostFunction<LandmarkCost, ceres::CENTRAL>(
        new LandmarkCost{&problem, 1.0 / kLandmarkSigma}, ceres::TAKE_OWNERSHIP, nd);
    cost->AddParameterBlock(ShapeParams::kCount);
    cost->AddParameterBlock(ExpressionStyle::kNumFields);
    cost->AddParameterBlock(kPoseSize);
    cost->SetNumResiduals(problem.num_residuals);
    cp.AddResidualBlock(cost, nullptr, shape.data(), style.data(), pose.data());
    cp.AddResidualBlock(
        new ceres::AutoDiffCostFunction<ShapePriorCost, ShapeParams::kCount, ShapeParams::kCount>(
            new ShapePriorCost{1.0 / options.shape_prior_sigma}),
        nullptr, shape.data());
    for (int i = 0; i < ShapeParams::kCount; ++i) {  // keep the head buildable
      cp.SetParameterLowerBound(shape.data(), i, 0.5);
      cp.SetParameterUpperBound(shape.data(), i, 1.6);
    }
    if (!options.fit_shape) cp.SetParameterBlockConstant(shape.data());
    if (options.fit_style) {
      cp.AddResidualBlock(new ceres::AutoDiffCostFunction<StylePriorCost, ExpressionStyle::kNumFields,
                                                          ExpressionStyle::kNumFields>(new StylePriorCost{
                              1.0 / options.style_gain_sigma, 1.0 / options.style_offset_sigma}),
                          nullptr, style.data());
      // ExpressionStyle::Validate's ranges, less the numeric differences' step (1e-3 of the value).
      for (int i = 0; i < ExpressionStyle::kNumFields; ++i) {
        const bool gain = i < ExpressionStyle::kNumGains;
        const double lo = gain ? ExpressionStyle::kMinGain : 1.0 - ExpressionStyle::kMaxOffset;
        const double hi = gain ? ExpressionStyle::kMaxGain : 1.0 + ExpressionStyle::kMaxOffset;
        cp.SetParameterLowerBound(style.data(), i, lo * (1.0 + 2e-3));
        cp.SetParameterUpperBound(style.data(), i, hi * (1.0 - 2e-3));
      }
    } else {
      cp.SetParameterBlockConstant(style.data());
    }
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_QR;
    so.max_num_iterations = options.max_iterations;
    so.num_threads = 1;  // deterministic
    so.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &cp, &summary);
    if (!summary.IsSolutionUsable()) return Status::Error("face fit: the solver failed: " + summary.message);
    fit.iterations += static_cast<int>(summary.iterations.size());

    // Outliers: farther than outlier_iod and 3x the median landmark error.
    const std::vector<std::vector<double>> errors = problem.Errors(shape.data(), style.data(), pose.data());
    std::vector<double> all;
    for (const auto& row : errors) all.insert(all.end(), row.begin(), row.end());
    std::nth_element(all.begin(), all.begin() + all.size() / 2, all.end());
    const double cut = std::max(options.outlier_iod, 3.0 * all[all.size() / 2]);
    int removed = 0;
    double sum2 = 0, worst = 0;
    int used = 0, residuals = 0;
    for (size_t k = 0; k < errors.size(); ++k)
      for (int i = 0; i < kNumLandmarks; ++i) {
        const bool inlier = errors[k][i] <= cut;
        if (!inlier && problem.weight[k][i] > 0) ++removed;
        problem.weight[k][i] = inlier ? 1.0 : 0.0;
        if (inlier) sum2 += errors[k][i] * errors[k][i], ++used, residuals += frames[k].landmarks_3d ? 3 : 2;
        worst = std::max(worst, errors[k][i]);
      }
    fit.rms_iod = std::sqrt(sum2 / std::max(used, 1));
    fit.max_iod = worst;
    fit.landmarks_used = used;
    fit.sum_squares = sum2;
    fit.residual_count = residuals;
    if (removed == 0) break;
  }
  std::array<float, ShapeParams::kCount> values;
  for (int i = 0; i < ShapeParams::kCount; ++i) values[i] = static_cast<float>(shape[i]);
  fit.shape = ShapeParams::FromArray(values);
  fit.style = StyleFromBlock(style.data());
  fit.head_from_world = PoseToSimilarity(pose.data(), base);
  return fit;
}

}  // namespace

Result<FaceFit> FitFaceModel(std::span<const FitFrame> frames, const FaceFitOptions& options) {
  ICEF_RETURN_IF_ERROR(options.Validate().WithContext("face fit options"));
  ICEF_RETURN_IF_ERROR(CheckFrames(frames));
  FaceFitOptions generic_options = options;
  generic_options.fit_style = false;
  ICEF_ASSIGN_OR_RETURN(FaceFit generic, FitOnce(frames, generic_options));
  if (!options.fit_style) return generic;
  ICEF_ASSIGN_OR_RETURN(FaceFit styled, FitOnce(frames, options));
  styled.generic_style_rms_iod = generic.rms_iod;
  generic.generic_style_rms_iod = generic.rms_iod;
  // 17 more parameters must earn their keep (an F test of the nested fits): landmarks the generic
  // style explains as well, such as a tracked dataset's (the generic face model's own), hold no
  // style, only noise the extra fields would fit.
  const double p = ExpressionStyle::kNumFields;
  const double dof = styled.residual_count - ShapeParams::kCount - kPoseSize - p;
  const double gained = generic.sum_squares - styled.sum_squares;
  styled.style_f = dof > 0 && styled.sum_squares > 0
                       ? (gained / p) / (styled.sum_squares / dof)
                       : (gained > 0 ? std::numeric_limits<double>::infinity() : 0.0);
  generic.style_f = styled.style_f;
  if (styled.style_f >= options.style_min_f) return styled;
  generic.style_rejected = true;
  return generic;
}

}  // namespace icef::face
