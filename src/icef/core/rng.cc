#include "icef/core/rng.h"

#include <cmath>
#include <cstdio>

namespace icef {

double Rng::Normal() {
  double u1 = UniformDouble();
  double u2 = UniformDouble();
  if (u1 < 1e-300) u1 = 1e-300;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

std::string Rng::ToString() const {
  char buf[64];
  std::snprintf(buf, sizeof buf, "Rng(key=%016llx, counter=%llu)", static_cast<unsigned long long>(key_),
                static_cast<unsigned long long>(counter_));
  return buf;
}

}  // namespace icef
