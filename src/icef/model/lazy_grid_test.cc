#include "icef/model/lazy_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "icef/core/parallel.h"

namespace icef {
namespace {

// A smooth field (2 channels) with a jump across the plane x = 0.31 (anchors on either side are far
// apart) and no anchor beyond |y| > 0.8.
bool Field(const Vec3f& x, float* values, Vec3f* anchor) {
  const bool left = x.x() < 0.31f;
  values[0] = std::sin(x.x()) * std::cos(x.y()) + (left ? 0.f : 1.f);
  values[1] = 0.5f * x.z() * x.z();
  if (std::abs(x.y()) > 0.8f) {
    values[0] = values[1] = 0.f;
    return false;
  }
  *anchor = Vec3f(left ? -1.f : 1.f, x.y(), x.z());
  return true;
}

LazyGrid::Options GridOptions() {
  LazyGrid::Options o;
  o.cell = 0.05f;
  o.max_anchor_spread = 4;
  o.tolerance = {1e-3f, 1e-3f};
  return o;
}

TEST(LazyGrid, InterpolatesWhereSmoothAndIsExactAtTheJump) {
  const LazyGrid grid(Vec3f(-1, -1, -1), Vec3f(1, 1, 1), GridOptions(), Field);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1.2f, 1.2f);  // some points outside the box
  int interpolated = 0, near_jump_interpolated = 0;
  float worst = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3f x(u(rng), u(rng), u(rng));
    float got[2], want[2];
    Vec3f anchor;
    const bool used_grid = grid.At(x, got);
    Field(x, want, &anchor);
    interpolated += used_grid;
    // The cells from x = 0.30 to 0.35 (cell 0.05 from -1) hold the jump.
    if (used_grid && x.x() > 0.302f && x.x() < 0.348f && std::abs(x.y()) < 0.75f) ++near_jump_interpolated;
    worst = std::max({worst, std::abs(got[0] - want[0]), std::abs(got[1] - want[1])});
  }
  EXPECT_GT(interpolated, 20000 / 2);    // most of the box is smooth
  EXPECT_EQ(near_jump_interpolated, 0);  // cells across the jump: f's own values
  EXPECT_LT(worst, 3e-3f);               // the tolerance at the centres, a little more inside
  const LazyGrid::Counts counts = grid.counts();
  EXPECT_GT(counts.bricks, 0);
  EXPECT_LT(counts.interpolated, counts.cells);
  EXPECT_NE(grid.ToString().find("bricks built"), std::string::npos);
}

// zero_outside: points outside the box are 0 without asking f.
TEST(LazyGrid, ZeroOutsideAsksNothingThere) {
  int calls = 0;
  LazyGrid::Options o = GridOptions();
  o.zero_outside = true;
  const LazyGrid grid(Vec3f(-1, -1, -1), Vec3f(1, 1, 1), o, [&](const Vec3f& x, float* v, Vec3f* a) {
    ++calls;
    return Field(x, v, a);
  });
  float values[2] = {1, 1};
  EXPECT_TRUE(grid.At(Vec3f(3, 0, 0), values));
  EXPECT_EQ(values[0], 0.f);
  EXPECT_EQ(values[1], 0.f);
  EXPECT_EQ(calls, 0);
  grid.At(Vec3f(0, 0, 0), values);  // inside: its brick is sampled
  EXPECT_GT(calls, 0);
}

// smooth_beyond: a field anchored on the plane z = 0 (distance |z|) that jumps across x = 0.31.
// Cells that reach within smooth_beyond of the plane keep the tests (the jump's cells are f's own
// values); the cells beyond are interpolated without them (the jump is smoothed over one cell).
TEST(LazyGrid, SmoothBeyondInterpolatesFarFromTheAnchors) {
  const auto field = [](const Vec3f& x, float* values, Vec3f* anchor) {
    values[0] = x.x() < 0.31f ? 0.f : 1.f;
    values[1] = x.y();
    *anchor = Vec3f(x.x(), x.y(), 0.f);
    return true;
  };
  LazyGrid::Options o = GridOptions();
  o.smooth_beyond = 0.3f;
  const LazyGrid grid(Vec3f(-1, -1, -1), Vec3f(1, 1, 1), o, field);
  const float diagonal = std::sqrt(3.f) * o.cell;
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  int near_interpolated = 0, near = 0, far_exact = 0, far = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3f x(0.302f + 0.046f * 0.5f * (u(rng) + 1.f), u(rng), u(rng));  // in the jump's cells
    float got[2];
    const bool used_grid = grid.At(x, got);
    EXPECT_GE(got[0], 0.f);
    EXPECT_LE(got[0], 1.f);
    if (std::abs(x.z()) < o.smooth_beyond) near_interpolated += used_grid, ++near;
    if (std::abs(x.z()) > o.smooth_beyond + 2 * diagonal) far_exact += !used_grid, ++far;
  }
  EXPECT_GT(near, 1000);
  EXPECT_GT(far, 1000);
  EXPECT_EQ(near_interpolated, 0);  // within smooth_beyond of the anchors: the tests hold
  EXPECT_EQ(far_exact, 0);          // beyond it (and a cell's reach): smooth
}

// The answers depend on the point alone: the same for queries in another order, on more threads.
TEST(LazyGrid, AnswersDoNotDependOnTheOrderOrThreads) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::vector<Vec3f> points(5000);
  for (Vec3f& p : points) p = Vec3f(u(rng), u(rng), u(rng));
  const LazyGrid a(Vec3f(-1, -1, -1), Vec3f(1, 1, 1), GridOptions(), Field);
  std::vector<float> first(2 * points.size());
  for (size_t i = 0; i < points.size(); ++i) a.At(points[i], first.data() + 2 * i);
  const LazyGrid b(Vec3f(-1, -1, -1), Vec3f(1, 1, 1), GridOptions(), Field);
  std::vector<float> second(2 * points.size());
  ParallelForChunks(Executor(2), static_cast<int64_t>(points.size()), 7, [&](int64_t begin, int64_t end) {
    for (int64_t j = end - 1; j >= begin; --j) {
      const size_t i = points.size() - 1 - static_cast<size_t>(j);
      b.At(points[i], second.data() + 2 * i);
    }
  });
  EXPECT_EQ(first, second);
}

}  // namespace
}  // namespace icef
