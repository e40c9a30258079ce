#include "icef/synth/head_model.h"

#include <cmath>

#include "icef/core/rng.h"

namespace icef::synth {

HeadModel::HeadModel(const IdentityParams& identity)
    : identity_(identity), face_(identity.shape, identity.style) {
  BuildMoles();
}

void HeadModel::BuildMoles() {
  const face::FaceGeometry& g = face_.geometry();
  const Vec3f back(0.f, 0.f, -1.f);
  auto front = [&](float x, float y) { return face_.ProjectNeutral(Vec3f(x, y, 0.6f), back); };
  // Points on the face away from the eyes and the lips.
  Rng rng(identity_.detail_seed, StreamId("synth.moles"));
  for (int attempt = 0; attempt < 200 && static_cast<int>(moles_.size()) < identity_.num_moles; ++attempt) {
    const float x = static_cast<float>(rng.Uniform(-0.17, 0.17));
    const float y = static_cast<float>(rng.Uniform(-0.27, 0.16));
    const float radius = static_cast<float>(rng.Uniform(0.004, 0.008));
    bool ok = std::abs(y - g.mouth_y) > 0.035f || std::abs(x) > g.mouth_half_width + 0.02f;
    for (int side = 0; side < 2; ++side)
      ok = ok && Vec2f(x - g.eye_c[side].x(), y - g.eye_c[side].y()).norm() > 0.06f;
    ok = ok && std::abs(x) > 0.035f;  // keep the nose clean
    if (!ok) continue;
    moles_.push_back(front(x, y));
    mole_radii_.push_back(radius);
  }
}

std::string HeadModel::ToString() const { return "HeadModel(" + identity_.ToString() + ")"; }

}  // namespace icef::synth
