#include "icef/render/occupancy_grid.h"

#include <gtest/gtest.h>

namespace icef {
namespace {

OccupancyGrid::DensityQuery Sphere(Vec3f centre, float radius, float value) {
  return [=](const float* p, int64_t n, float* sigma) {
    for (int64_t i = 0; i < n; ++i)
      sigma[i] = (Vec3f(p[3 * i], p[3 * i + 1], p[3 * i + 2]) - centre).norm() < radius ? value : 0.f;
  };
}

TEST(OccupancyGridTest, StartsFullAndLearnsASphere) {
  OccupancyGridOptions o;
  o.resolution = 16;
  o.dilation = 0;
  o.query_batch = 1000;  // several batches
  OccupancyGrid grid(Aabb(), o);
  EXPECT_EQ(grid.NumOccupied(), grid.num_cells());
  // Decay 0.95 and threshold 0.01: the initial fill must decay away, so force it to empty first.
  grid.Fill(false);
  grid.Update(Sphere(Vec3f(0.3f, 0, 0), 0.4f, 5.f), 1, 0);
  EXPECT_TRUE(grid.IsOccupied(Vec3f(0.3f, 0, 0)));
  EXPECT_FALSE(grid.IsOccupied(Vec3f(-0.8f, 0.8f, 0.8f)));
  EXPECT_FALSE(grid.IsOccupied(Vec3f(0, 0, 2)));  // outside the aabb
  const double fraction = grid.OccupiedFraction();
  // Sphere volume 0.268 of an 8-unit box is 3.4%; cells partially covered may or may not hit.
  EXPECT_GT(fraction, 0.01);
  EXPECT_LT(fraction, 0.08);
}

TEST(OccupancyGridTest, DilationGrowsAndDecayForgets) {
  OccupancyGridOptions o;
  o.resolution = 16;
  o.dilation = 0;
  o.decay = 0.5f;
  o.threshold = 1.f;
  OccupancyGrid plain(Aabb(), o);
  o.dilation = 2;
  OccupancyGrid dilated(Aabb(), o);
  const auto query = Sphere(Vec3f(0, 0, 0), 0.3f, 8.f);
  plain.Fill(false);
  dilated.Fill(false);
  plain.Update(query, 1, 0);
  dilated.Update(query, 1, 0);
  EXPECT_GT(dilated.NumOccupied(), plain.NumOccupied());
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x)
        if (plain.IsCellOccupied(x, y, z)) {
          EXPECT_TRUE(dilated.IsCellOccupied(x, y, z));
        }
  // Density vanishes: 8 -> 4 -> 2 -> 1 (not > 1): occupied for two more updates, then empty.
  const auto empty = Sphere(Vec3f::Zero(), 0.f, 0.f);
  plain.Update(empty, 1, 1);
  EXPECT_GT(plain.NumOccupied(), 0);
  plain.Update(empty, 1, 2);
  EXPECT_GT(plain.NumOccupied(), 0);
  plain.Update(empty, 1, 3);
  EXPECT_EQ(plain.NumOccupied(), 0);
}

TEST(OccupancyGridTest, DeterministicAndRestorable) {
  OccupancyGridOptions o;
  o.resolution = 8;
  OccupancyGrid a(Aabb(), o), b(Aabb(), o);
  auto query = [](const float* p, int64_t n, float* sigma) {
    for (int64_t i = 0; i < n; ++i) sigma[i] = std::max(0.f, 1.f - 3.f * std::abs(p[3 * i] * p[3 * i + 1]));
  };
  a.Update(query, 9, 4);
  b.Update(query, 9, 4);
  EXPECT_EQ(a.densities(), b.densities());
  OccupancyGrid c(Aabb(), o);
  ASSERT_TRUE(c.SetDensities(a.densities()).ok());
  EXPECT_EQ(c.NumOccupied(), a.NumOccupied());
  EXPECT_FALSE(c.SetDensities(std::vector<float>(3)).ok());
}

TEST(OccupancyGridTest, PartialUpdatesQueryAboutThatFractionOfCells) {
  OccupancyGridOptions o;
  o.resolution = 16;
  o.update_fraction = 0.25f;
  OccupancyGrid grid(Aabb(), o);
  int64_t queried = 0;
  grid.Update(
      [&](const float*, int64_t n, float* sigma) {
        queried += n;
        for (int64_t i = 0; i < n; ++i) sigma[i] = 1.f;
      },
      3, 0);
  EXPECT_GT(queried, 900);  // 0.25 * 4096 = 1024
  EXPECT_LT(queried, 1150);
  int64_t high = 0;
  for (float d : grid.densities()) high += d == 1.f ? 1 : 0;
  EXPECT_EQ(high, queried);  // exactly the queried cells took the new density
}

TEST(OccupancyGridTest, ValidateRejectsBadOptions) {
  OccupancyGridOptions o;
  EXPECT_TRUE(o.Validate().ok());
  o.decay = 1.5f;
  EXPECT_FALSE(o.Validate().ok());
  o = OccupancyGridOptions();
  o.resolution = 0;
  EXPECT_FALSE(o.Validate().ok());
  o = OccupancyGridOptions();
  o.update_fraction = 0.f;
  EXPECT_FALSE(o.Validate().ok());
}

TEST(OccupancyGridTest, AllowedCellsAreAHardPrior) {
  OccupancyGridOptions o;
  o.resolution = 8;
  o.dilation = 1;
  OccupancyGrid grid(Aabb{}, o);
  std::vector<uint8_t> allowed(grid.num_cells(), 0);
  allowed[grid.CellIndex(3, 3, 3)] = 1;
  allowed[grid.CellIndex(4, 3, 3)] = 1;
  ASSERT_TRUE(grid.SetAllowed(allowed).ok());
  EXPECT_EQ(grid.NumOccupied(), 2);  // fully occupied start, restricted to the allowed cells
  grid.Update([](const float*, int64_t n, float* sigma) { std::fill(sigma, sigma + n, 100.f); }, 1, 1);
  EXPECT_EQ(grid.NumOccupied(), 2);  // dense everywhere, dilated, but still only the allowed cells
  EXPECT_TRUE(grid.IsCellOccupied(3, 3, 3));
  EXPECT_FALSE(grid.IsCellOccupied(5, 3, 3));
  grid.Fill(true);
  EXPECT_EQ(grid.NumOccupied(), 2);
  EXPECT_FALSE(grid.SetAllowed(std::vector<uint8_t>(5, 1)).ok());
  ASSERT_TRUE(grid.SetAllowed({}).ok());
  EXPECT_EQ(grid.NumOccupied(), grid.num_cells());
}

// With an allowed set, Update asks only for the cells within the dilation of an allowed cell, and
// the bits are exactly those of a grid that asked for every cell (restricted to the allowed set).
TEST(OccupancyGridTest, UpdatesQueryOnlyCellsThatCanReachAnAllowedCell) {
  OccupancyGridOptions o;
  o.resolution = 16;
  o.dilation = 1;
  o.decay = 0.5f;
  o.threshold = 1.f;
  o.query_batch = 100;  // several batches
  for (const float fraction : {1.f, 0.5f}) {
    o.update_fraction = fraction;
    OccupancyGrid every(Aabb(), o), restricted(Aabb(), o);
    std::vector<uint8_t> allowed(every.num_cells(), 0);
    for (int z = 4; z < 9; ++z)
      for (int y = 5; y < 11; ++y)
        for (int x = 3; x < 7; ++x) allowed[every.CellIndex(x, y, z)] = 1;
    ASSERT_TRUE(restricted.SetAllowed(allowed).ok());
    every.Fill(false);
    restricted.Fill(false);
    // A dense ball that straddles the allowed box's faces, then moves away (decay must act alike).
    int64_t queried = 0;
    for (int step = 0; step < 4; ++step) {
      const Vec3f centre(-0.4f + 0.3f * float(step), -0.1f, -0.2f);
      const auto ball = Sphere(centre, 0.35f, 6.f);
      every.Update(ball, 7, step);
      restricted.Update(
          [&](const float* p, int64_t n, float* sigma) {
            queried += n;
            for (int64_t i = 0; i < n; ++i) {
              const Vec3f q(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
              const Vec3f cell = ((q - Aabb().min).cwiseQuotient(Aabb().Extent()) * 16.f);
              // Only cells at Chebyshev distance <= 1 from the box [3,7) x [5,11) x [4,9).
              EXPECT_TRUE(cell.x() >= 2 && cell.x() < 8 && cell.y() >= 4 && cell.y() < 12 && cell.z() >= 3 &&
                          cell.z() < 10)
                  << q.transpose();
            }
            ball(p, n, sigma);
          },
          7, step);
      int64_t expected_occupied = 0;
      for (int64_t c = 0; c < every.num_cells(); ++c) {
        const int x = int(c % 16), y = int((c / 16) % 16), z = int(c / 256);
        const bool want = allowed[c] && every.IsCellOccupied(x, y, z);
        EXPECT_EQ(restricted.IsCellOccupied(x, y, z), want) << "cell " << x << "," << y << "," << z;
        expected_occupied += want;
      }
      EXPECT_GT(expected_occupied, 0) << "step " << step;
    }
    // 6 x 8 x 7 cells can reach the box; all 16^3 would be 4096 per update.
    EXPECT_LE(queried, 4 * 6 * 8 * 7) << fraction;
    EXPECT_GT(queried, 0);
  }
}

TEST(OccupancyGridTest, QueriedCellsAddCellsOutsideTheAllowedSet) {
  OccupancyGridOptions o;
  o.resolution = 8;
  o.dilation = 0;
  OccupancyGrid grid(Aabb{}, o);
  std::vector<uint8_t> allowed(grid.num_cells(), 0);
  allowed[grid.CellIndex(1, 1, 1)] = 1;
  ASSERT_TRUE(grid.SetAllowed(allowed).ok());
  ASSERT_EQ(grid.NumOccupied(), 1);
  // Dense at cell (5, 5, 5) only (centre (0.375, 0.375, 0.375), cell size 0.25): that cell is
  // added, outside the grid's allowed set; the grid's own occupied cell stays.
  int64_t queried = 0;
  auto one_cell = [&](const float* p, int64_t n, float* sigma) {
    queried += n;
    for (int64_t i = 0; i < n; ++i)
      sigma[i] = (Vec3f(p[3 * i], p[3 * i + 1], p[3 * i + 2]) - Vec3f(0.375f, 0.375f, 0.375f)).norm() < 0.01f
                     ? 1.f
                     : 0.f;
  };
  const OccupancyGrid render = grid.WithQueriedCells(one_cell);
  EXPECT_EQ(queried, grid.num_cells());
  EXPECT_TRUE(render.IsCellOccupied(1, 1, 1));
  EXPECT_TRUE(render.IsCellOccupied(5, 5, 5));
  EXPECT_EQ(render.NumOccupied(), 2);
  EXPECT_TRUE(render.allowed().empty());
  EXPECT_EQ(grid.NumOccupied(), 1);  // the grid itself is unchanged
  // Dilation grows the added cells, but only into cells the query allows (sigma >= 0).
  o.dilation = 1;
  OccupancyGrid dilated(Aabb{}, o);
  dilated.Fill(false);
  EXPECT_EQ(dilated.WithQueriedCells([](const float*, int64_t n, float* s) { std::fill(s, s + n, 0.f); })
                .NumOccupied(),
            0);
  EXPECT_EQ(dilated.WithQueriedCells(one_cell).NumOccupied(), 27);
  const OccupancyGrid half = dilated.WithQueriedCells([&](const float* p, int64_t n, float* sigma) {
    one_cell(p, n, sigma);
    for (int64_t i = 0; i < n; ++i)
      if (p[3 * i] > 0.4f) sigma[i] = -1.f;  // cells x >= 6 not allowed
  });
  EXPECT_EQ(half.NumOccupied(), 18);  // x in {4, 5} of the 3 x 3 x 3 block
  // Stride 2: one query per 2 x 2 x 2 block; a dense block occupies its 8 cells (dilated: 4^3).
  queried = 0;
  const OccupancyGrid coarse = dilated.WithQueriedCells(
      [&](const float* p, int64_t n, float* sigma) {
        queried += n;
        for (int64_t i = 0; i < n; ++i)  // block (2, 2, 2): cells 4..5, centre (0.25, 0.25, 0.25)
          sigma[i] = (Vec3f(p[3 * i], p[3 * i + 1], p[3 * i + 2]) - Vec3f(0.25f, 0.25f, 0.25f)).norm() < 0.01f
                         ? 1.f
                         : 0.f;
      },
      2);
  EXPECT_EQ(queried, 4 * 4 * 4);
  EXPECT_EQ(coarse.NumOccupied(), 4 * 4 * 4);
  EXPECT_TRUE(coarse.IsCellOccupied(3, 3, 3));
  EXPECT_TRUE(coarse.IsCellOccupied(6, 6, 6));
  EXPECT_FALSE(coarse.IsCellOccupied(7, 6, 6));
}

}  // namespace
}  // namespace icef
