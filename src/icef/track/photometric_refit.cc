// The tracker's photometric refit (track_fit_internal.h, track/photometric.h).
#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

#include "icef/math/ray.h"
#include "icef/track/photometric.h"
#include "icef/track/track_fit_internal.h"

namespace icef::track::internal {

namespace {

// Expression states by weights for one face model (the refit holds the shape): Ceres evaluates every
// point's residual at the same perturbed weights, so a few states serve them all.
class StateCache {
 public:
  StateCache(const face::FaceModel* model, double max_expression)
      : model_(model), max_expression_(max_expression) {}
  const face::ExpressionState& For(const double* e) {
    const std::vector<float> beta = ClampedExpression(e, max_expression_);
    for (const auto& [key, state] : entries_)
      if (key == beta) return *state;
    if (entries_.size() >= 64) entries_.pop_front();
    entries_.emplace_back(beta, std::make_unique<face::ExpressionState>(model_->Prepare(beta)));
    return *entries_.back().second;
  }

 private:
  const face::FaceModel* model_;
  double max_expression_;
  std::deque<std::pair<std::vector<float>, std::unique_ptr<face::ExpressionState>>> entries_;
};

struct PhotoContext {
  const face::FaceModel* model = nullptr;
  StateCache* states = nullptr;
  double sigma = 0.05;  // TrackFitOptions::photometric_sigma
};

// A head-frame point's pixel in a frame for a pose.
std::optional<Vec2d> ProjectHeadPoint(const FrameProblem& fp, const Shared& shared, const double* pose,
                                      const Vec3f& x_head) {
  const Camera camera = FrameCamera(fp, shared, pose);
  Vec3d x = x_head.cast<double>();
  if (shared.known_cameras) x = SharedSimilarity(shared, pose).ApplyInverse(x);
  if (const auto p = camera.Project(x)) return p->uv;
  return std::nullopt;
}

// The colour a frame shows at a neutral-face point for (expression, pose): the point carried by the
// face model's inverse warp, projected, sampled.
bool PointColour(const FrameProblem& fp, const Shared& shared, const PhotoContext& ctx,
                 const BlurredImage& image, const Vec3f& x_c, const double* expression, const double* pose,
                 Vec3d* rgb) {
  const Vec3f x = ctx.model->InverseWarp(x_c, ctx.states->For(expression));
  const auto uv = ProjectHeadPoint(fp, shared, pose, x);
  return uv && image.Sample(uv->x(), uv->y(), rgb);
}

// A frame's exposure and white balance: colour -> gain * colour, per channel (photos differ in both).
struct Exposure {
  Vec3d gain = Vec3d::Ones();
  Vec3d Apply(const Vec3d& rgb) const { return gain.cwiseProduct(rgb); }
};

// One point in one frame: (colour found - the point's colour) / sigma, over the blocks (expression,
// pose, point colour). Jacobians by finite differences with FrameCost's steps (the colour's is -1 /
// sigma). A point that leaves the image contributes nothing.
class ColourCost : public ceres::CostFunction {
 public:
  ColourCost(const FrameProblem* fp, const Shared* shared, const PhotoContext* ctx, const BlurredImage* image,
             const Exposure* exposure, const Vec3f& x_c)
      : fp_(fp), shared_(shared), ctx_(ctx), image_(image), exposure_(exposure), x_c_(x_c) {
    mutable_parameter_block_sizes()->push_back(kExpr);
    mutable_parameter_block_sizes()->push_back(shared->known_cameras ? kSharedPose : kPhotoPose);
    mutable_parameter_block_sizes()->push_back(3);
    set_num_residuals(3);
  }

  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override {
    Vec3d rgb;
    const bool seen = Colour(params[0], params[1], &rgb);
    const double inv = 1.0 / ctx_->sigma;
    for (int c = 0; c < 3; ++c) residuals[c] = seen ? (rgb[c] - params[2][c]) * inv : 0.0;
    if (!jacobians) return true;
    const int sizes[2] = {kExpr, shared_->known_cameras ? kSharedPose : kPhotoPose};
    if (jacobians[2])
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) jacobians[2][3 * r + c] = seen && r == c ? -inv : 0.0;
    for (int block = 0; block < 2; ++block) {
      if (!jacobians[block]) continue;
      std::vector<double> x(params[block], params[block] + sizes[block]);
      const double* e = block == 0 ? x.data() : params[0];
      const double* pose = block == 1 ? x.data() : params[1];
      for (int j = 0; j < sizes[block]; ++j) {
        const double h = block == 0 ? 1e-2 : 1e-3;
        const double x0 = x[j];
        const bool forward = block == 0 && x0 < h;
        Vec3d a = rgb, b = rgb;
        x[j] = x0 + h;
        const bool seen_a = Colour(e, pose, &a);
        bool seen_b = true;
        if (!forward) {
          x[j] = x0 - h;
          seen_b = Colour(e, pose, &b);
        }
        x[j] = x0;
        const double span = forward ? h : 2 * h;
        for (int r = 0; r < 3; ++r)
          jacobians[block][r * sizes[block] + j] =
              seen && seen_a && seen_b ? (a[r] - b[r]) / span * inv : 0.0;
      }
    }
    return true;
  }

 private:
  bool Colour(const double* expression, const double* pose, Vec3d* rgb) const {
    if (!PointColour(*fp_, *shared_, *ctx_, *image_, x_c_, expression, pose, rgb)) return false;
    *rgb = exposure_->Apply(*rgb);
    return true;
  }

  const FrameProblem* fp_;
  const Shared* shared_;
  const PhotoContext* ctx_;
  const BlurredImage* image_;
  const Exposure* exposure_;
  Vec3f x_c_;
};

// The points a frame sees at (expression, pose): first along their camera ray (nothing of the face
// before them), facing the camera, inside the image.
std::vector<char> VisiblePoints(const FrameProblem& fp, const Shared& shared, const PhotoContext& ctx,
                                const BlurredImage& image, const std::vector<Vec3f>& points,
                                const double* expression, const double* pose) {
  const face::ExpressionState& state = ctx.states->For(expression);
  const face::ExpressionState copy = state;  // the cache may evict it below
  const Camera camera = FrameCamera(fp, shared, pose);
  Vec3d centre = camera.Center();
  if (shared.known_cameras) centre = SharedSimilarity(shared, pose).Apply(centre);
  std::vector<char> visible(points.size(), 0);
  for (size_t p = 0; p < points.size(); ++p) {
    const Vec3f x = ctx.model->InverseWarp(points[p], copy);
    const Vec3f to_point = x - centre.cast<float>();
    const float dist = to_point.norm();
    const Ray ray{centre.cast<float>(), to_point / dist};
    const float t = ctx.model->Trace(ray, std::max(0.f, dist - 1.5f), dist + 0.05f, copy);
    if (t < 0 || std::abs(t - dist) > 0.01f) continue;
    if (ctx.model->Normal(x, copy).dot(-ray.direction) < 0.2f) continue;
    Vec3d rgb;
    const auto uv = ProjectHeadPoint(fp, shared, pose, x);
    visible[p] = uv && image.Sample(uv->x(), uv->y(), &rgb);
  }
  return visible;
}

}  // namespace

// After the landmark fit: expressions and poses refined on the images, the shape held. For each blur
// (coarse, fine): the points each frame sees, their colours started at the mean of the frames that
// see them (a point needs two), then one solve over the landmark residuals and the colour residuals
// (Cauchy loss: specular highlights, hair, a hand), a frame's colour residuals weighted together as
// photometric_weight times its landmarks.
Status PhotometricRefit(std::vector<FrameProblem>& problems, Shared& shared, const TrackFitOptions& options,
                        Solution* s) {
  const int n = static_cast<int>(problems.size());
  const Solution landmark_fit = *s;
  std::array<float, kShape> shape;
  for (int i = 0; i < kShape; ++i) shape[i] = static_cast<float>(s->shape[i]);
  const face::FaceModel model(face::ShapeParams::FromArray(shape), options.style);
  const std::vector<Vec3f> points = CanonicalFaceSamples(model, options.photometric_points);
  StateCache states(&model, options.max_expression);
  const PhotoContext ctx{&model, &states, options.photometric_sigma};
  std::vector<int> all(n);
  for (int k = 0; k < n; ++k) all[k] = k;
  TrackFitOptions refit_options = options;
  refit_options.expression_prior_sigma = options.photometric_expression_prior_sigma;
  refit_options.expression_prior_laplace = options.photometric_expression_prior_laplace;
  for (const double blur_iod : {options.photometric_blur_coarse_iod, options.photometric_blur_fine_iod}) {
    std::vector<BlurredImage> images;
    std::vector<std::vector<char>> visible;
    for (int k = 0; k < n; ++k) {
      images.emplace_back(*problems[k].frame->photo, blur_iod * problems[k].iod_px);
      visible.push_back(VisiblePoints(problems[k], shared, ctx, images[k], points, s->expression[k].data(),
                                      PoseOf(*s, shared, k)));
    }
    // Each frame's colours at its visible points and its exposure: a gain per channel that brings
    // the median of its colours at the points every frame sees to the mean of all frames' medians
    // (the same points in each: a turned head shows more of its lit or its shaded side; medians: a
    // hand, a shadow or an open mouth in one photo barely move them). No such point: gains of 1.
    std::vector<std::vector<std::optional<Vec3d>>> sampled(n,
                                                           std::vector<std::optional<Vec3d>>(points.size()));
    for (int k = 0; k < n; ++k)
      for (size_t p = 0; p < points.size(); ++p) {
        Vec3d rgb;
        if (visible[k][p] && PointColour(problems[k], shared, ctx, images[k], points[p],
                                         s->expression[k].data(), PoseOf(*s, shared, k), &rgb))
          sampled[k][p] = rgb;
      }
    std::vector<Vec3d> median(n, Vec3d::Ones());
    for (int k = 0; k < n; ++k) {
      std::array<std::vector<double>, 3> values;
      for (size_t p = 0; p < points.size(); ++p) {
        const bool common =
            std::all_of(sampled.begin(), sampled.end(), [p](const auto& f) { return f[p].has_value(); });
        if (common)
          for (int c = 0; c < 3; ++c) values[c].push_back((*sampled[k][p])[c]);
      }
      for (int c = 0; c < 3 && !values[c].empty(); ++c) {
        std::nth_element(values[c].begin(), values[c].begin() + values[c].size() / 2, values[c].end());
        median[k][c] = std::max(values[c][values[c].size() / 2], 1e-3);
      }
    }
    Vec3d all_median = Vec3d::Zero();
    for (int k = 0; k < n; ++k) all_median += median[k] / n;
    std::vector<Exposure> exposure(n);
    for (int k = 0; k < n; ++k) exposure[k].gain = all_median.cwiseQuotient(median[k]);
    std::vector<std::array<double, 3>> colour(points.size(), {0, 0, 0});
    std::vector<int> seen_by(points.size(), 0);
    for (int k = 0; k < n; ++k)
      for (size_t p = 0; p < points.size(); ++p) {
        if (!sampled[k][p]) continue;
        const Vec3d rgb = exposure[k].Apply(*sampled[k][p]);
        for (int c = 0; c < 3; ++c) colour[p][c] += rgb[c];
        ++seen_by[p];
      }
    for (size_t p = 0; p < points.size(); ++p)
      for (int c = 0; c < 3; ++c) colour[p][c] /= std::max(seen_by[p], 1);

    ceres::Problem cp;
    const bool fit_pose = !(shared.known_cameras && options.photometric_hold_similarity);
    AddLandmarkBlocks(cp, problems, all, shared, refit_options, /*fit_shape=*/false, fit_pose, s);
    for (int k = 0; k < n; ++k) {
      int used = 0;
      for (size_t p = 0; p < points.size(); ++p) used += visible[k][p] && seen_by[p] >= 2;
      if (used == 0) continue;
      const double weight = options.photometric_weight * kNumLandmarks / used;
      double* pose = shared.known_cameras ? s->pose[0].data() : s->pose[k].data();
      for (size_t p = 0; p < points.size(); ++p) {
        if (!visible[k][p] || seen_by[p] < 2) continue;
        cp.AddResidualBlock(new ColourCost(&problems[k], &shared, &ctx, &images[k], &exposure[k], points[p]),
                            new ceres::ScaledLoss(new ceres::CauchyLoss(1.0), weight, ceres::TAKE_OWNERSHIP),
                            s->expression[k].data(), pose, colour[p].data());
      }
    }
    ICEF_RETURN_IF_ERROR(RunSolver(cp, options, s));

    // The report: each frame's colour residual over the points it sees (the last blur's).
    s->photometric_rms.assign(n, 0.0);
    s->photometric_used.assign(n, 0);
    for (int k = 0; k < n; ++k) {
      double sum2 = 0;
      for (size_t p = 0; p < points.size(); ++p) {
        Vec3d rgb;
        if (!visible[k][p] || seen_by[p] < 2 ||
            !PointColour(problems[k], shared, ctx, images[k], points[p], s->expression[k].data(),
                         PoseOf(*s, shared, k), &rgb))
          continue;
        sum2 += (exposure[k].Apply(rgb) - Vec3d(colour[p][0], colour[p][1], colour[p][2])).squaredNorm() / 3;
        ++s->photometric_used[k];
      }
      s->photometric_rms[k] = std::sqrt(sum2 / std::max(s->photometric_used[k], 1));
    }
  }
  // Photos whose colours still disagree do not show one consistently lit face (another light,
  // drawings on them): the colours then pull the fit somewhere wrong, so the landmark fit stands.
  // The (upper) median over the images: one image may disagree (a hand, the largest expressions,
  // whose shading the warp does not carry); the Cauchy loss takes care of it.
  std::vector<double> sorted = s->photometric_rms;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double median_rms = sorted[n / 2];
  if (median_rms > options.photometric_max_rms) {
    std::ostringstream why;
    why.precision(3);
    why << "not used: the images' colours disagree by a median RMS of " << median_rms << " > "
        << options.photometric_max_rms;
    Solution kept = landmark_fit;
    kept.iterations = s->iterations;
    kept.photometric_rms = s->photometric_rms;
    kept.photometric_used = s->photometric_used;
    *s = std::move(kept);
    s->photometric_note = why.str();
    return Status::Ok();
  }
  s->photometric_note = "used";
  return Status::Ok();
}

}  // namespace icef::track::internal
