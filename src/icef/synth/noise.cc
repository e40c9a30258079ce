#include "icef/synth/noise.h"

#include <cmath>

#include "icef/face/sdf_primitives.h"

namespace icef::synth {

uint32_t HashLattice(int x, int y, int z, uint32_t seed) {
  uint32_t h = seed * 0x9E3779B1u;
  h ^= static_cast<uint32_t>(x) * 0x85EBCA77u;
  h = (h << 13) | (h >> 19);
  h ^= static_cast<uint32_t>(y) * 0xC2B2AE3Du;
  h = (h << 17) | (h >> 15);
  h ^= static_cast<uint32_t>(z) * 0x27D4EB2Fu;
  h ^= h >> 16;
  h *= 0x7FEB352Du;
  h ^= h >> 15;
  h *= 0x846CA68Bu;
  h ^= h >> 16;
  return h;
}

namespace {
inline float Quintic(float t) { return t * t * t * (t * (t * 6.f - 15.f) + 10.f); }
inline float Lerp(float a, float b, float t) { return a + (b - a) * t; }
}  // namespace

float ValueNoise(const Vec3f& p, uint32_t seed) {
  const float fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy), iz = static_cast<int>(fz);
  const float tx = Quintic(p.x() - fx), ty = Quintic(p.y() - fy), tz = Quintic(p.z() - fz);
  auto v = [&](int dx, int dy, int dz) { return HashToUnit(HashLattice(ix + dx, iy + dy, iz + dz, seed)); };
  const float x00 = Lerp(v(0, 0, 0), v(1, 0, 0), tx), x10 = Lerp(v(0, 1, 0), v(1, 1, 0), tx);
  const float x01 = Lerp(v(0, 0, 1), v(1, 0, 1), tx), x11 = Lerp(v(0, 1, 1), v(1, 1, 1), tx);
  return 2.f * Lerp(Lerp(x00, x10, ty), Lerp(x01, x11, ty), tz) - 1.f;
}

float FractalNoise(const Vec3f& p, uint32_t seed, int octaves) {
  float sum = 0.f, amplitude = 1.f, norm = 0.f;
  Vec3f q = p;
  for (int o = 0; o < octaves; ++o) {
    sum += amplitude * ValueNoise(q, seed + 7919u * static_cast<uint32_t>(o));
    norm += amplitude;
    amplitude *= 0.5f;
    q = 2.03f * q + Vec3f(17.1f, 5.3f, 11.7f);
  }
  return sum / norm;
}

float CellSpots(const Vec3f& p, float frequency, float density, uint32_t seed) {
  const Vec3f q = p * frequency;
  const float fx = std::floor(q.x()), fy = std::floor(q.y()), fz = std::floor(q.z());
  const uint32_t h = HashLattice(static_cast<int>(fx), static_cast<int>(fy), static_cast<int>(fz), seed);
  if (HashToUnit(h) >= density) return 0.f;
  const uint32_t h2 = HashLattice(static_cast<int>(h), 3, 7, seed ^ 0xA511E9B3u);
  const uint32_t h3 = HashLattice(static_cast<int>(h2), 5, 11, seed ^ 0x63D83595u);
  const float radius = 0.12f + 0.13f * HashToUnit(h3);
  // Centre inside [0.25, 0.75]^3 of the cell so the spot never crosses the cell boundary.
  const Vec3f centre(fx + 0.25f + 0.5f * HashToUnit(h2), fy + 0.25f + 0.5f * HashToUnit(h2 * 0x9E3779B1u),
                     fz + 0.25f + 0.5f * HashToUnit(h3 * 0x85EBCA77u));
  const float r = (q - centre).norm() / radius;
  return 1.f - face::SmoothStep(0.6f, 1.f, r);
}

}  // namespace icef::synth
