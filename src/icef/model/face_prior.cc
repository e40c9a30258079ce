#include "icef/model/face_prior.h"

#include <sstream>
#include <vector>

#include "icef/face/expression.h"
#include "icef/face/face_model.h"
#include "icef/model/ict_prior.h"

namespace icef {

namespace {

constexpr float kJacobianStep = 1e-3f;  // head units (the head is 0.73 tall; the warp's windows span 0.03+)

class FacePrior final : public DeformationPrior {
 public:
  explicit FacePrior(const face::FaceFit& fit) : fit_(fit), model_(fit.shape, fit.style) {
    const face::Similarity& s = fit.head_from_world;
    head_from_world_ = (s.scale * s.rotation).cast<float>();
    world_from_head_ = (s.rotation.transpose() / s.scale).cast<float>();
    translation_ = s.translation.cast<float>();
    rotation_t_ = s.rotation.transpose().cast<float>();
    neutral_ = model_.Prepare(std::vector<float>(face::kNumExpressions, 0.f));
  }

  void Offsets(const Executor& executor, int64_t n, const float* positions, const float* betas,
               float* offsets) const override {
    ParallelFor(executor, n, [&](int64_t i0, int64_t i1, int) {
      StateCache cache;
      for (int64_t i = i0; i < i1; ++i) {
        const Vec3f x(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
        const face::ExpressionState& state = cache.Get(model_, betas + i * face::kNumExpressions);
        const Vec3f x_h = head_from_world_ * x + translation_;
        const Vec3f c = world_from_head_ * (model_.PriorWarp(x_h, state) - translation_);
        for (int a = 0; a < 3; ++a) offsets[3 * i + a] = c[a] - x[a];
      }
    });
  }

  void Cavity(const Executor& executor, int64_t n, const float* positions, const float* betas,
              uint8_t* inside) const override {
    ParallelFor(executor, n, [&](int64_t i0, int64_t i1, int) {
      StateCache cache;
      for (int64_t i = i0; i < i1; ++i) {
        const face::ExpressionState& state = cache.Get(model_, betas + i * face::kNumExpressions);
        inside[i] = 0;
        if (!state.cavity) continue;
        const Vec3f x(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
        const Vec3f q = (head_from_world_ * x + translation_ - state.cavity_c).cwiseQuotient(state.cavity_r);
        inside[i] = q.squaredNorm() < 1.f ? 1 : 0;
      }
    });
  }

  bool Normals(const Executor& executor, int64_t n, const float* positions, const float* betas,
               float* observed, float* canonical) const override {
    ParallelFor(executor, n, [&](int64_t i0, int64_t i1, int) {
      StateCache cache;
      std::vector<Vec3f> canonical_points(size_t(i1 - i0)), neutral_normals(size_t(i1 - i0));
      for (int64_t i = i0; i < i1; ++i) {
        const Vec3f x(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
        const face::ExpressionState& state = cache.Get(model_, betas + i * face::kNumExpressions);
        canonical_points[size_t(i - i0)] = model_.PriorWarp(head_from_world_ * x + translation_, state);
      }
      // The neutral surface's normal g at the canonical point P(x): the range's all at once.
      model_.CanonicalNormals(canonical_points, neutral_, neutral_normals.data());
      for (int64_t i = i0; i < i1; ++i) {
        const Vec3f x(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
        const face::ExpressionState& state = cache.Get(model_, betas + i * face::kNumExpressions);
        const Vec3f x_h = head_from_world_ * x + translation_;
        // g carried back through the prior warp: the surface the warp makes of the neutral one is
        // d(x) = d_neutral(P(x)), whose gradient is J^T g with J = dP/dx (central differences). Where
        // the warp is a translation the two agree (s = 1) whatever the expression. Six warps cost a
        // fraction of the four signed distances of the expressed model's own normal.
        const Vec3f g = neutral_normals[size_t(i - i0)];
        Vec3f carried = g;
        if (!state.neutral) {
          Mat3f jacobian;
          for (int a = 0; a < 3; ++a) {
            const Vec3f e = Vec3f::Unit(a) * kJacobianStep;
            jacobian.col(a) =
                (model_.PriorWarp(x_h + e, state) - model_.PriorWarp(x_h - e, state)) / (2.f * kJacobianStep);
          }
          const Vec3f m = jacobian.transpose() * g;
          if (m.norm() > 0.f) carried = m.normalized();
        }
        const Vec3f n_obs = rotation_t_ * carried;
        const Vec3f n_can = rotation_t_ * g;
        for (int a = 0; a < 3; ++a) {
          observed[3 * i + a] = n_obs[a];
          canonical[3 * i + a] = n_can[a];
        }
      }
    });
    return true;
  }

  int expression_dims() const override { return face::kNumExpressions; }
  std::string ToString() const override {
    std::ostringstream os;
    os << "FacePrior(" << fit_.shape.ToString() << ", " << fit_.style.ToString() << ", "
       << fit_.head_from_world.ToString() << ")";
    return os.str();
  }

 private:
  // Samples come in runs of one expression (a ray, a frame): prepare each expression once per run.
  struct StateCache {
    std::vector<float> key;
    face::ExpressionState state;
    const face::ExpressionState& Get(const face::FaceModel& model, const float* beta) {
      if (key.empty() || !std::equal(key.begin(), key.end(), beta)) {
        key.assign(beta, beta + face::kNumExpressions);
        // Negative weights (not a face-model expression) act as zero: the warp is defined for >= 0.
        std::vector<float> clamped(key);
        for (float& v : clamped) v = std::isfinite(v) ? std::max(v, 0.f) : 0.f;
        state = model.Prepare(clamped);
      }
      return state;
    }
  };

  face::FaceFit fit_;
  face::FaceModel model_;
  Mat3f head_from_world_, world_from_head_, rotation_t_;
  face::ExpressionState neutral_;
  Vec3f translation_;
};

}  // namespace

Status CheckFaceModelExpressions(const std::vector<std::string>& expression_names,
                                 const std::string& origin) {
  const std::vector<std::string> want = face::ExpressionNames();
  if (expression_names == want) return Status::Ok();
  std::string got;
  for (const std::string& s : expression_names) got += (got.empty() ? "" : ", ") + s;
  return Status::Error(
      origin + ": the face-model prior needs the face model's " + std::to_string(want.size()) +
      " expressions (jaw_open, smile_left, ...; docs/face_model.md), but expression_names are [" +
      (got.empty() ? std::string("none") : got) +
      "]: re-express the dataset in them with `icef track DATASET --keep-cameras --out NEW`, or "
      "train it with a method without the prior (icef, warp, nerface)");
}

Result<face::FaceFit> FitFaceModelToDataset(const Dataset& dataset, const face::FaceFitOptions& options) {
  ICEF_RETURN_IF_ERROR(CheckFaceModelExpressions(dataset.expression_names, dataset.root.string()));
  std::vector<face::FitFrame> frames;
  for (size_t k = 0; k < dataset.train.size(); ++k) {
    const Frame& f = dataset.train[k];
    face::FitFrame ff;
    ff.expression = f.expression;
    for (float& v : ff.expression) v = std::max(v, 0.f);
    if (f.landmarks_3d) {
      ff.landmarks_3d = f.landmarks_3d;
    } else if (f.landmarks_2d) {
      ff.landmarks_2d = f.landmarks_2d;
      ff.camera = f.camera;
    } else {
      continue;
    }
    frames.push_back(std::move(ff));
  }
  if (frames.empty())
    return Status::Error(
        dataset.root.string() +
        ": the face-model fit needs landmarks (landmarks_3d or landmarks_2d) on the training frames; "
        "add them with `icef landmarks`");
  Result<face::FaceFit> fit = face::FitFaceModel(frames, options);
  if (!fit.ok()) return fit.status().WithContext(dataset.root.string());
  return fit;
}

Result<std::unique_ptr<DeformationPrior>> MakeFacePrior(const ModelSetup& setup) {
  if (setup.ict_fit) {
    ICEF_ASSIGN_OR_RETURN(std::shared_ptr<const face::IctModel> model, face::IctModel::LoadDefault());
    if (!IsIctExpressionSpace(*model, setup.expression_names))
      return Status::Error("model setup: an ICT-FaceKit fit, but the expressions are not ICT-FaceKit's");
    ICEF_ASSIGN_OR_RETURN(
        std::unique_ptr<IctPrior> prior,
        IctPrior::Create(std::move(model), setup.ict_fit->identity, setup.ict_fit->head_from_world));
    return std::unique_ptr<DeformationPrior>(std::move(prior));
  }
  ICEF_RETURN_IF_ERROR(CheckFaceModelExpressions(setup.expression_names, "model setup"));
  if (!setup.face_fit)
    return Status::Error("model setup: the face-model prior needs a face-model fit (none saved)");
  return std::unique_ptr<DeformationPrior>(std::make_unique<FacePrior>(*setup.face_fit));
}

}  // namespace icef
