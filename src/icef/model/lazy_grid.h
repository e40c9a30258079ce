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
// f agree within each channel's tolerance. Elsewhere (the cells that fail, points outside the box unless
// zero_outside) the answer is f's own.
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
  static constexpr int kBrickCells = 8;  // cells per brick side

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

  int channels() const { return static_cast<int>(options_.tolerance.size()); }
  // Bricks sampled so far, and of their cells how many are interpolated.
  struct Counts {
    int64_t bricks = 0, cells = 0, interpolated = 0;
  };
  Counts counts() const;
  std::string ToString() const;

 private:
  struct Brick;
  static constexpr int kLocks = 64;  // a brick is built under lock (its index mod kLocks)

  const Brick& BrickAt(int bx, int by, int bz) const;
  Brick* Build(int bx, int by, int bz) const;

  Vec3f lo_;
  Options options_;
  Function f_;
  int cells_[3] = {1, 1, 1};                                   // per axis
  int bricks_[3] = {1, 1, 1};                                  // per axis
  std::unique_ptr<std::atomic<const Brick*>[]> bricks_built_;  // nullptr until built
  mutable std::mutex locks_[kLocks];
};

}  // namespace icef
