// A costly vector field f: R^3 -> R^C sampled on a regular grid and interpolated trilinearly inside
// the cells where that reproduces f; f itself everywhere else. Built lazily: a brick of 8^3 cells is
// sampled (its 9^3 corners and its cells' centres) the first time a point falls in it, so a caller
// pays for the part of space it asks about.
//
// A cell is interpolated when it lies far from every anchor (smooth_beyond), or when (1) f gives an anchor at
// all 8 corners or at none of them (or at any number, with mixed_anchors: f then fades continuously to where
// it has no anchor), (2) the anchors lie within max_anchor_spread cells of one another (an anchor is where
// f's value comes from, e.g. the closest surface point: corners whose anchors are far apart straddle a jump
// of f, such as the medial axis between two lips), and (3) at the cell's centre, trilinear interpolation and
// f agree within each channel's tolerance; that test may be kept per group of channels (Options::group),
// and a point is interpolated when the groups of the channels asked for pass. A cell that fails is
// refined (Options::refine): the first time a point falls in it, it is split into refine^3 cells
// sampled and tested the same way (their spread in their own cells, smooth_beyond not applied), and a
// point in a fine cell that passes is interpolated there. Elsewhere (the fine cells that fail, every
// failing cell without refine, points outside the box unless zero_outside) the answer is f's own.
// Refining pays where many points fall in a failing cell: a cell that fails for its curvature passes
// at a finer size, and of a cell a jump crosses, only the fine cells along the jump fail.
//
// Determinism: every corner, centre and answer is a function of the point alone (given a
// deterministic f), so results do not depend on the thread count or on the order of queries.
// Thread safety: At() may be called concurrently; f must then be safe to call concurrently.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "icef/math/types.h"

namespace icef {

class LazyGrid {
 public:
  static constexpr int kBrickCells = 8;    // cells per brick side
  static constexpr int kMaxChannels = 16;  // the most channels f may give
  static constexpr int kMaxRefine = 16;    // the most fine cells per side of a refined cell

  // f(x, values[channels], anchor) -> whether f has an anchor at x (then *anchor is set).
  using Function = std::function<bool(const Vec3f& x, float* values, Vec3f* anchor)>;

  struct Options {
    float cell = 0.25f;             // side of a cell, in the units of the points
    float max_anchor_spread = 4.f;  // in cells: the largest extent of a cell's corner anchors
    std::vector<float> tolerance;   // per channel: |interpolated - f| allowed at a cell's centre
    bool mixed_anchors = false;     // cells with anchors at some corners only may be interpolated
    bool zero_outside = false;      // f is 0 outside the box: answer 0 there without asking f
    // A cell all of whose points lie at least this far from every corner's anchor (the corners'
    // smallest distance to their anchors less the cell's diagonal; a corner without one counts as
    // far) is interpolated without the tests: the grid's smooth interpolation is the answer there,
    // jumps of f included. Infinity: never.
    float smooth_beyond = INFINITY;
    // Fine cells per side of a refined cell (0 or 1: failing cells are not refined). A refined cell
    // costs f at (refine + 1)^3 corners and refine^3 centres, once. At most kMaxRefine.
    int refine = 0;
    // Per channel: its group (0 to 7), or empty: one group. A cell passes the tolerance test for a
    // group when every channel of that group does, and At() interpolates the channels it is asked
    // for where their groups pass (anchors and smooth_beyond decide for all groups alike).
    std::vector<int> group;
  };

  // The grid covers [lo, hi] (cells of options.cell; the last ones reach past hi). Requires
  // lo < hi, cell > 0, one finite tolerance >= 0 per channel.
  LazyGrid(const Vec3f& lo, const Vec3f& hi, Options options, Function f);
  ~LazyGrid();
  LazyGrid(const LazyGrid&) = delete;
  LazyGrid& operator=(const LazyGrid&) = delete;

  // values[channels] at x; true when interpolated (or 0 outside the box, zero_outside), false when
  // f's own.
  bool At(const Vec3f& x, float* values) const;
  // Channels [first, first + count) of the above into values[count] (the same values; only those
  // channels are interpolated).
  bool At(const Vec3f& x, int first, int count, float* values) const;

  int channels() const { return static_cast<int>(options_.tolerance.size()); }
  // Bricks sampled so far, and of their cells how many are interpolated (for every group); cells
  // refined so far, and of their fine cells how many are interpolated.
  struct Counts {
    int64_t bricks = 0, cells = 0, interpolated = 0;
    int64_t refined = 0, fine_cells = 0, fine_interpolated = 0;
  };
  Counts counts() const;
  std::string ToString() const;

 private:
  struct Block;
  struct Brick;
  static constexpr int kLocks = 64;  // a brick or a refined cell is built under lock (its index mod kLocks)

  // f at the (n + 1)^3 corners of n^3 cells of side h from origin, and each cell's tests.
  void Sample(const Vec3f& origin, float h, int n, Block* block) const;
  const Brick& BrickAt(int64_t index, int bx, int by, int bz) const;
  Brick* Build(int bx, int by, int bz) const;
  // The refined block of a failing cell (cell: its index in the grid), built the first time.
  const Block& RefinedAt(const Brick& brick, int64_t brick_index, int cell_index, const int cell[3]) const;

  uint8_t GroupBit(int channel) const {
    return static_cast<uint8_t>(1u << (options_.group.empty() ? 0 : options_.group[channel]));
  }

  Vec3f lo_;
  Options options_;
  uint8_t all_groups_ = 0;  // the bits of every channel's group
  Function f_;
  int cells_[3] = {1, 1, 1};                                   // per axis
  int bricks_[3] = {1, 1, 1};                                  // per axis
  std::unique_ptr<std::atomic<const Brick*>[]> bricks_built_;  // nullptr until built
  mutable std::mutex locks_[kLocks];
};

}  // namespace icef
