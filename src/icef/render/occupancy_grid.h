// Occupancy grid in observation space (docs/design.md §3): a dense density grid over the aabb whose
// occupied cells (density above a threshold, dilated) are where the sampler puts samples. The grid
// knows no fields: Update() takes a caller-provided density query over a batch of world positions.
// Covering all training expressions is the caller's job (query each expression and take the max).
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/math/ray.h"
#include "icef/math/types.h"

namespace icef {

struct OccupancyGridOptions {
  int resolution = 64;     // cells per axis (resolution^3 cells over the aabb)
  float decay = 0.9f;      // EMA: stored density <- max(decay * stored, new density) per update
  float threshold = 0.5f;  // a cell is occupied when its stored density (sigma, 1/world units) exceeds this
  int dilation = 1;        // occupied cells are dilated by this many cells (Chebyshev distance)
  int64_t query_batch = 65536;  // positions per density-query call
  float update_fraction = 1.f;  // fraction of cells re-queried per Update (a random subset; all cells decay)

  bool operator==(const OccupancyGridOptions&) const = default;
  Status Validate() const;
  std::string ToString() const;
};

class OccupancyGrid {
 public:
  // Fills sigma[i] with the density at positions[3 i .. 3 i + 2] (world frame), for i in [0, n).
  using DensityQuery = std::function<void(const float* positions, int64_t n, float* sigma)>;

  // A grid over `aabb` with every cell occupied (nothing is skipped before the first update).
  // Checks options.Validate() and aabb validity (programming errors).
  OccupancyGrid(const Aabb& aabb, const OccupancyGridOptions& options);

  // Decays every stored density by `decay`, queries one jittered point per selected cell (Rng keyed
  // on (seed, "occupancy", step, cell); with update_fraction < 1 a cell is selected with that
  // probability) and keeps max(decayed, queried); then recomputes the occupied bits (threshold +
  // dilation). With an allowed set, cells farther than the dilation from every allowed cell are
  // not queried (they could not change a bit). Deterministic for (seed, step) and the query.
  void Update(const DensityQuery& query, uint64_t seed, int64_t step);

  // The grid for rendering one expression: the cells occupied here (bits, hull included) plus the
  // cells `cell_query` finds dense. The query gets the centre of every block of stride^3 cells
  // (stride 1: every cell centre; in batches of query_batch) and returns its density, or a
  // negative value where the block is not allowed (e.g. outside a hull); blocks above the
  // threshold are dilated by the grid's dilation (in cells), and the dilation stays within the
  // allowed blocks. The result has no allowed set of its own and is meant for sampling only (its
  // stored densities are this grid's).
  OccupancyGrid WithQueriedCells(const DensityQuery& cell_query, int stride = 1) const;

  // True when the cell containing p (world frame) is occupied; false outside the aabb.
  bool IsOccupied(const Vec3f& p) const {  // inline: the sampler asks for every sample
    const int64_t c = CellOf(p);
    return c >= 0 && bits_[c] != 0;
  }
  bool IsCellOccupied(int x, int y, int z) const { return bits_[CellIndex(x, y, z)] != 0; }
  // Marks every cell occupied (or empty) and sets the stored densities to +threshold*2 (or 0).
  // Cells outside the allowed set (SetAllowed) stay empty.
  void Fill(bool occupied);
  // A hard prior (e.g. the visual hull of the training masks): cells with allowed[c] == 0 are
  // never occupied, whatever their density. Empty vector = every cell allowed. Error on a size
  // mismatch.
  Status SetAllowed(std::vector<uint8_t> allowed);
  const std::vector<uint8_t>& allowed() const { return allowed_; }

  int resolution() const { return options_.resolution; }
  const Aabb& aabb() const { return aabb_; }
  const OccupancyGridOptions& options() const { return options_; }
  int64_t num_cells() const {
    return int64_t(options_.resolution) * options_.resolution * options_.resolution;
  }
  int64_t NumOccupied() const;
  double OccupiedFraction() const { return double(NumOccupied()) / double(num_cells()); }
  // Stored densities [resolution^3], index (z * R + y) * R + x; for checkpoints.
  const std::vector<float>& densities() const { return density_; }
  // Restores densities saved from densities() and recomputes the bits; error on a size mismatch.
  Status SetDensities(std::vector<float> densities);
  // The cell index of p, or -1 outside the aabb.
  int64_t CellOf(const Vec3f& p) const {
    const Vec3f q = (p - aabb_.min).cwiseProduct(inv_cell_size_);
    const int r = options_.resolution;
    int c[3];
    for (int a = 0; a < 3; ++a) {
      if (!(q[a] >= 0.f && q[a] <= float(r))) return -1;  // also rejects NaN
      c[a] = std::min(int(q[a]), r - 1);
    }
    return CellIndex(c[0], c[1], c[2]);
  }
  int64_t CellIndex(int x, int y, int z) const {
    return (int64_t(z) * options_.resolution + y) * options_.resolution + x;
  }

  std::string ToString() const;

 private:
  void RecomputeBits();
  // Dilates `bits` [R^3] by options_.dilation cells (a (2k+1)^3 box), in place.
  void Dilate(std::vector<uint8_t>* bits) const;

  Aabb aabb_;
  OccupancyGridOptions options_;
  Vec3f inv_cell_size_;
  std::vector<float> density_;    // [R^3]
  std::vector<uint8_t> bits_;     // [R^3] 1 = occupied (after dilation)
  std::vector<uint8_t> allowed_;  // [R^3] or empty: 0 = never occupied
  // [R^3] or empty (query every cell): the cells Update queries, the allowed set dilated as the
  // bits are. A cell beyond it cannot make an allowed cell occupied, so its density is not asked
  // for: with a visual hull that carves most of the box, most of the cost of an update.
  std::vector<uint8_t> queried_;
};

}  // namespace icef
