// The face model: a procedural parametric head given as an implicit surface (signed distance
// bound) in the head frame (+y up, the face looks down +z, the subject's left is +x; the head is
// ~0.75 tall, centred near the origin, inside [-1, 1]^3 with the neck cut at y = -0.8). Its shape
// comes from ShapeParams, its expressions from the named weights of face/expression.h; it knows
// nothing of albedo or rendering. See docs/face_model.md.
//
// Expressions are a smooth, compactly supported space warp from the observed point x to the
// canonical (neutral) point x_c = Warp(x), so the neutral surface (and anything attached to it,
// such as a texture) moves with the expression:
//   distance(x, beta) = carve(neutral_with_eyelids(Warp(x), beta), mouth_cavity(x, beta)).
// Eyelids are SDF caps over the eyeballs whose edge angle follows eye_close_*; jaw_open rotates
// the lower face about a hinge and carves a mouth cavity between the lips. How strongly, where and
// how asymmetrically each expression acts is the model's ExpressionStyle (generic by default;
// synthetic subjects have their own).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "icef/face/expression.h"
#include "icef/face/expression_style.h"
#include "icef/face/shape_params.h"
#include "icef/math/ray.h"
#include "icef/math/types.h"

namespace icef::face {

// The part of the head closest to a point.
enum class Material : uint8_t { kSkin, kEyeball, kEyelid, kMouthCavity };

// Anchor positions of the face parts derived from the shape (head frame, canonical space).
// Index 0 of the paired arrays is the subject's right side (x < 0), index 1 the left (x > 0).
struct FaceGeometry {
  Vec3f cranium_c, cranium_r, face_c, face_r, chin_c, chin_r;
  std::array<Vec3f, 2> cheek_c, ear_c, eye_c, brow_ridge_c, nostril_c;
  Vec3f cheek_r, ear_r, brow_ridge_r, nostril_r;
  float eye_r = 0, lid_thickness = 0, brow_y = 0;
  Vec3f nose_top, nose_tip;
  float nose_top_r = 0, nose_tip_r = 0;
  float mouth_y = 0, mouth_half_width = 0, lip_z = 0;
  Vec3f upper_lip_c, upper_lip_r, lower_lip_c, lower_lip_r;
  Vec3f neck_a, neck_b;
  float neck_r = 0, neck_cut_y = 0;
  Vec3f jaw_hinge;  // the generic hinge (FaceModel moves it by the style's jaw_hinge_dy/dz)
  float lid_upper_neutral = 0, lid_lower = 0;  // eyelid edge elevations (radians)

  static FaceGeometry FromShape(const ShapeParams& p);
};

// An expression vector prepared for fast evaluation (derived angles, cavity, active terms).
struct ExpressionState {
  std::array<float, kNumExpressions> beta{};
  std::array<float, kNumExpressions> styled{};  // beta[i] * style.WeightGain(i): what the warp uses
  float jaw_angle = 0;                          // radians about the hinge's x axis
  std::array<float, 2> lid_upper{};             // upper-lid edge elevation per eye (radians)
  bool cavity = false;                          // mouth cavity carved
  Vec3f cavity_c = Vec3f::Zero(), cavity_r = Vec3f::Ones();  // observation space
  float step_scale = 0.8f;  // sphere-tracing step factor (smaller for larger warps)
  bool neutral = true;      // all weights zero
};

class FaceModel {
 public:
  // ICEF_CHECK fails unless style.Validate() is OK.
  explicit FaceModel(const ShapeParams& shape, const ExpressionStyle& style = ExpressionStyle::Generic());

  const ShapeParams& shape() const { return shape_; }
  const ExpressionStyle& style() const { return style_; }
  const FaceGeometry& geometry() const { return geometry_; }
  // A box holding the surface for expression weights up to ~2 (for ray bounds).
  Aabb Bounds() const;

  // Checks the weights with ICEF_CHECK (kNumExpressions values, finite, >= 0; use
  // ValidateExpression for user input) and precomputes the expression terms.
  ExpressionState Prepare(std::span<const float> expression) const;
  ExpressionState Prepare(const std::vector<float>& expression) const {
    return Prepare(std::span<const float>(expression));
  }

  // Observation -> canonical point for the expression (identity where no term is active).
  Vec3f Warp(const Vec3f& x, const ExpressionState& state) const;
  // The face model's whole observation -> canonical map for a deformation model (docs/design.md §2.1):
  // Warp, then the eyelid slide. In the surface itself a closing eye is a lid cap whose edge angle
  // changes (not a warp); the slide stands for it as a warp: a point on the closing upper lid, at
  // elevation theta about the eye centre's x axis between the state's lid edge and the top of the
  // eye, maps to the neutral lid by rotating [edge, top] onto [neutral edge, top], so a canonical
  // (neutral) head with open eyes renders closed eyes. Exposed eyeball and skin are unchanged.
  Vec3f PriorWarp(const Vec3f& x, const ExpressionState& state) const;
  // The eyelid slide alone, on a canonical point of Warp.
  Vec3f LidSlide(const Vec3f& x_c, const ExpressionState& state) const;

  // Canonical -> observation point: the inverse of Warp by fixed-point iteration (the warp is a
  // small smooth displacement). jaw_weight_override >= 0 forces the jaw-rotation weight.
  Vec3f InverseWarp(const Vec3f& x_c, const ExpressionState& state, float jaw_weight_override = -1.f) const;

  // Signed distance bound at observation point x.
  float Distance(const Vec3f& x, const ExpressionState& state) const;
  // Distance plus the material of the closest part and the canonical point.
  struct Sample {
    float distance;
    Material material;
    Vec3f canonical;
  };
  Sample Evaluate(const Vec3f& x, const ExpressionState& state) const;
  // Surface normal (unit, observation space) by central differences of Distance.
  Vec3f Normal(const Vec3f& x, const ExpressionState& state) const;
  // Normals of the canonical surface (the state's lids, no warp, no mouth cavity) at many canonical
  // points, vectorised; for a neutral state (or one that only closes the eyes: no warp, no cavity)
  // each equals Normal(point, state) to float round-off. normals: [points.size()].
  void CanonicalNormals(std::span<const Vec3f> points, const ExpressionState& state, Vec3f* normals) const;

  // Sphere-traces the ray in [t_near, t_far]; returns the hit distance t or a negative value.
  float Trace(const Ray& ray, float t_near, float t_far, const ExpressionState& state, int max_steps = 192,
              float epsilon = 2.5e-4f) const;

  // The 68 iBUG-68 landmarks in the head frame for the expression (observation space). The
  // neutral landmarks do not depend on the style.
  std::array<Vec3f, 68> Landmarks(const ExpressionState& state) const;
  // The same with each landmark's canonical point moved by canonical_offsets[i] (head units) before
  // the warp: another detector's convention of where the 68 points lie (track/detector_landmarks.h).
  std::array<Vec3f, 68> Landmarks(const ExpressionState& state,
                                  std::span<const Vec3f, 68> canonical_offsets) const;
  // Canonical (neutral) landmarks.
  const std::array<Vec3f, 68>& NeutralLandmarks() const { return neutral_landmarks_; }
  // The first crossing of the neutral surface (outside -> inside, or inside -> outside when the
  // origin is inside) along origin + t * normalised(dir), t in [0, 2]: a 0.002 march, then 30
  // bisection steps. Canonical space. ICEF_CHECK fails when nothing is crossed.
  Vec3f ProjectNeutral(const Vec3f& origin, const Vec3f& dir) const;

  std::string ToString() const;

 private:
  // Neutral surface with eyelids at the state's lid angles (canonical space); material optional.
  float CanonicalDistance(const Vec3f& x_c, const ExpressionState& state, Material* material) const;
  // CanonicalDistance without material at many points (a loop that vectorises). distances: [points.size()].
  void CanonicalDistances(std::span<const Vec3f> points, const ExpressionState& state,
                          float* distances) const;
  static constexpr float kNormalStep = 4e-4f;  // Normal()'s finite-difference step (head units)
  // Backward displacement (x_c - x) of the jaw rotation and of every bump term.
  Vec3f JawDisplacement(const Vec3f& x, float angle, float weight_override) const;
  Vec3f BumpDisplacement(const Vec3f& x, const ExpressionState& state) const;
  void BuildNeutralLandmarks();

  ShapeParams shape_;
  ExpressionStyle style_;
  FaceGeometry geometry_;
  Vec3f jaw_hinge_;  // geometry_.jaw_hinge moved by the style's hinge offset
  ExpressionState neutral_state_;
  std::array<Vec3f, 68> neutral_landmarks_;
};

}  // namespace icef::face
