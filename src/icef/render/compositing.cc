#include "icef/render/compositing.h"

#include <sstream>

namespace icef {

Status CompositeOptions::Validate() const {
  if (!(transmittance_eps >= 0.0 && transmittance_eps < 1.0))
    return Status::Error("compositing.transmittance_eps must be in [0, 1)");
  return Status::Ok();
}

std::string CompositeOptions::ToString() const {
  std::ostringstream os;
  os << "CompositeOptions(transmittance_eps=" << transmittance_eps << ")";
  return os.str();
}

namespace {
template <typename T>
void CheckShapes(const CompositeInputs<T>& in) {
  const size_t n = in.sigma.size();
  const size_t rays = in.ray_offset.size();
  ICEF_CHECK(in.rgb.size() == 3 * n && in.t.size() == n && in.dt.size() == n,
             "composite: sample array sizes");
  ICEF_CHECK(in.ray_count.size() == rays, "composite: ray_count size");
  ICEF_CHECK(in.background.size() == 3 || in.background.size() == 3 * rays, "composite: background size");
}
template <typename T>
const T* BackgroundOf(const CompositeInputs<T>& in, int64_t r) {
  return in.background.size() == 3 ? in.background.data() : in.background.data() + 3 * r;
}
}  // namespace

template <typename T>
void CompositeForward(const CompositeInputs<T>& in, const CompositeOptions& options, const Executor& executor,
                      CompositeOutputs<T>* out) {
  CheckShapes(in);
  const int64_t rays = int64_t(in.ray_offset.size());
  out->color.resize(3 * rays);
  out->opacity.resize(rays);
  out->depth.resize(rays);
  out->weights.resize(in.sigma.size());
  out->num_used.resize(rays);
  const T eps = T(options.transmittance_eps);
  ParallelFor(executor, rays, [&](int64_t begin, int64_t end, int) {
    for (int64_t r = begin; r < end; ++r) {
      const int64_t o = in.ray_offset[r];
      out->num_used[r] =
          CompositeRayForward<T>(in.ray_count[r], in.sigma.data() + o, in.rgb.data() + 3 * o, in.t.data() + o,
                                 in.dt.data() + o, BackgroundOf(in, r), eps, out->color.data() + 3 * r,
                                 &out->opacity[r], &out->depth[r], out->weights.data() + o);
    }
  });
}

template <typename T>
void CompositeBackward(const CompositeInputs<T>& in, const CompositeOutputs<T>& forward,
                       const CompositeOutputGradients<T>& grads, const Executor& executor,
                       std::vector<T>* d_sigma, std::vector<T>* d_rgb) {
  CheckShapes(in);
  const int64_t rays = int64_t(in.ray_offset.size());
  ICEF_CHECK(int64_t(forward.num_used.size()) == rays, "composite backward: forward outputs missing");
  ICEF_CHECK(int64_t(grads.d_color.size()) == 3 * rays, "composite backward: d_color size");
  ICEF_CHECK(grads.d_opacity.empty() || int64_t(grads.d_opacity.size()) == rays, "d_opacity size");
  ICEF_CHECK(grads.d_depth.empty() || int64_t(grads.d_depth.size()) == rays, "d_depth size");
  ICEF_CHECK(grads.d_weights.empty() || grads.d_weights.size() == in.sigma.size(), "d_weights size");
  d_sigma->resize(in.sigma.size());
  d_rgb->resize(in.rgb.size());
  ParallelFor(executor, rays, [&](int64_t begin, int64_t end, int) {
    for (int64_t r = begin; r < end; ++r) {
      const int64_t o = in.ray_offset[r];
      CompositeRayBackward<T>(in.ray_count[r], forward.num_used[r], in.sigma.data() + o,
                              in.rgb.data() + 3 * o, in.t.data() + o, in.dt.data() + o, BackgroundOf(in, r),
                              grads.d_color.data() + 3 * r,
                              grads.d_opacity.empty() ? T(0) : grads.d_opacity[r],
                              grads.d_depth.empty() ? T(0) : grads.d_depth[r],
                              grads.d_weights.empty() ? nullptr : grads.d_weights.data() + o,
                              d_sigma->data() + o, d_rgb->data() + 3 * o);
    }
  });
}

template void CompositeForward<float>(const CompositeInputs<float>&, const CompositeOptions&, const Executor&,
                                      CompositeOutputs<float>*);
template void CompositeForward<double>(const CompositeInputs<double>&, const CompositeOptions&,
                                       const Executor&, CompositeOutputs<double>*);
template void CompositeBackward<float>(const CompositeInputs<float>&, const CompositeOutputs<float>&,
                                       const CompositeOutputGradients<float>&, const Executor&,
                                       std::vector<float>*, std::vector<float>*);
template void CompositeBackward<double>(const CompositeInputs<double>&, const CompositeOutputs<double>&,
                                        const CompositeOutputGradients<double>&, const Executor&,
                                        std::vector<double>*, std::vector<double>*);

}  // namespace icef
