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

// refine: a cell the jump crosses is split into fine cells; those beside the jump are interpolated,
// those across it stay f's own, and one channel asked alone is that channel of the whole answer.
TEST(LazyGrid, RefinedCellsInterpolateBesideTheJump) {
  LazyGrid::Options o = GridOptions();
  o.refine = 4;  // fine cells of 0.0125: the jump at x = 0.31 lies in [0.3, 0.3125]
  int calls = 0;
  const LazyGrid grid(Vec3f(-1, -1, -1), Vec3f(1, 1, 1), o, [&](const Vec3f& x, float* v, Vec3f* a) {
    ++calls;
    return Field(x, v, a);
  });
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.7f, 0.7f);
  int beside = 0, beside_interpolated = 0, across_interpolated = 0;
  float worst = 0;
  for (int i = 0; i < 4000; ++i) {
    const float along = 0.3f + 0.05f * (0.5f * (u(rng) / 0.7f) + 0.5f);  // in the jump's cells
    const Vec3f x(along, u(rng), u(rng));
    float got[2], want[2], alone;
    Vec3f anchor;
    const bool used_grid = grid.At(x, got);
    EXPECT_EQ(grid.At(x, 1, 1, &alone), used_grid);
    EXPECT_EQ(alone, got[1]);
    Field(x, want, &anchor);
    worst = std::max({worst, std::abs(got[0] - want[0]), std::abs(got[1] - want[1])});
    if (along > 0.3135f) beside_interpolated += used_grid, ++beside;
    if (along > 0.3005f && along < 0.3095f) across_interpolated += used_grid;
  }
  EXPECT_GT(beside, 2000);
  EXPECT_EQ(beside_interpolated, beside);  // without refine: none (InterpolatesWhereSmooth...)
  EXPECT_EQ(across_interpolated, 0);
  EXPECT_LT(worst, 3e-3f);
  const LazyGrid::Counts counts = grid.counts();
  EXPECT_GT(counts.refined, 0);
  EXPECT_EQ(counts.fine_cells, 64 * counts.refined);
  EXPECT_LT(counts.fine_interpolated, counts.fine_cells);
  EXPECT_GT(counts.fine_interpolated, counts.fine_cells / 2);
  // A refined cell is sampled once: asking its points again costs f only where they are exact.
  const int before = calls;
  float got[2];
  grid.At(Vec3f(0.33f, 0.1f, 0.1f), got);
  EXPECT_EQ(calls, before);
}

// group: channel 1 bends too sharply for the tolerance (|x|^3 / 0.01 about x = 0.31) while channel 0
// is linear; with a group each, channel 0 is interpolated where channel 1 is f's own.
TEST(LazyGrid, GroupsPassTheirOwnTests) {
  const auto field = [](const Vec3f& x, float* values, Vec3f* anchor) {
    values[0] = 2.f * x.y();
    const float d = x.x() - 0.31f;
    values[1] = std::abs(d) * d * d / 0.01f;
    *anchor = x;
    return true;
  };
  LazyGrid::Options o = GridOptions();
  o.group = {0, 1};
  const LazyGrid grouped(Vec3f(-1, -1, -1), Vec3f(1, 1, 1), o, field);
  o.group = {};
  const LazyGrid together(Vec3f(-1, -1, -1), Vec3f(1, 1, 1), o, field);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.9f, 0.9f);
  int first_exact = 0, second_exact = 0, together_exact = 0;
  for (int i = 0; i < 5000; ++i) {
    const Vec3f x(u(rng), u(rng), u(rng));
    float v[2], both[2];
    first_exact += !grouped.At(x, 0, 1, v);
    second_exact += !grouped.At(x, 1, 1, v + 1);
    together_exact += !together.At(x, both);
    EXPECT_NEAR(v[0], 2.f * x.y(), 1e-5f);
    EXPECT_EQ(grouped.At(x, 0, 1, v), true);
  }
  EXPECT_EQ(first_exact, 0);
  EXPECT_GT(second_exact, 100);
  EXPECT_EQ(together_exact, second_exact);
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
  LazyGrid::Options o = GridOptions();
  o.refine = 3;
  const LazyGrid a(Vec3f(-1, -1, -1), Vec3f(1, 1, 1), o, Field);
  std::vector<float> first(2 * points.size());
  for (size_t i = 0; i < points.size(); ++i) a.At(points[i], first.data() + 2 * i);
  const LazyGrid b(Vec3f(-1, -1, -1), Vec3f(1, 1, 1), o, Field);
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
