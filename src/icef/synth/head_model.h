// A synthetic subject: the face model (face::FaceModel, geometry and expressions) with a
// procedural albedo (skin, pores, freckles, moles, lips, brows, hair, eyes, eyelids, mouth
// cavity) that is a function of the canonical point, so the texture moves with every expression.
// The ground-truth renderer draws it; everything geometric goes through face().
#pragma once

#include <string>
#include <vector>

#include "icef/face/face_model.h"
#include "icef/math/types.h"
#include "icef/synth/identity.h"

namespace icef::synth {

class HeadModel {
 public:
  explicit HeadModel(const IdentityParams& identity);

  const IdentityParams& identity() const { return identity_; }
  // The subject's face model (built from identity().shape and identity().style).
  const face::FaceModel& face() const { return face_; }

  // Albedo (RGB in [0, 1]) of the surface point: canonical point sample.canonical for
  // skin/eyes/eyelids (so the texture moves with the expression), observation point x for the
  // mouth cavity.
  Vec3f Albedo(const face::FaceModel::Sample& sample, const Vec3f& x,
               const face::ExpressionState& state) const;

  std::string ToString() const;

 private:
  Vec3f SkinAlbedo(const Vec3f& p) const;
  Vec3f EyeAlbedo(const Vec3f& p, int side) const;
  Vec3f LidAlbedo(const Vec3f& p, const face::ExpressionState& state) const;
  Vec3f CavityAlbedo(const Vec3f& x, const face::ExpressionState& state) const;
  // Places identity().num_moles moles on the neutral face, drawn from Rng(detail_seed, "synth.moles").
  void BuildMoles();

  IdentityParams identity_;
  face::FaceModel face_;
  std::vector<Vec3f> moles_;  // canonical surface points
  std::vector<float> mole_radii_;
};

}  // namespace icef::synth
