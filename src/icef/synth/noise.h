// Deterministic procedural noise for the head's albedo: integer hashing keyed on an identity seed,
// 3D value noise and fractal sums. Pure functions of (point, seed): no state, thread-safe.
#pragma once

#include <cstdint>

#include "icef/math/types.h"

namespace icef::synth {

// 32-bit hash of a lattice point and a seed.
uint32_t HashLattice(int x, int y, int z, uint32_t seed);
// Uniform in [0, 1) from a hash.
inline float HashToUnit(uint32_t h) { return static_cast<float>(h >> 8) * (1.f / 16777216.f); }

// Smooth (quintic-interpolated) value noise in [-1, 1], lattice spacing 1.
float ValueNoise(const Vec3f& p, uint32_t seed);
// Sum of `octaves` value-noise octaves (frequency x2, amplitude x0.5), normalised to [-1, 1].
float FractalNoise(const Vec3f& p, uint32_t seed, int octaves);

// Sparse round spots on a lattice of cell size 1/frequency: each cell holds at most one spot
// (with probability `density`) of radius in [0.12, 0.25] cells, fully inside its cell. Returns the
// spot coverage in [0, 1] (1 at the centre, smooth edge).
float CellSpots(const Vec3f& p, float frequency, float density, uint32_t seed);

}  // namespace icef::synth
