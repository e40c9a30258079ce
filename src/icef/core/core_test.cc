#include <gtest/gtest.h>

#include <sstream>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/progress.h"
#include "icef/core/rng.h"
#include "icef/core/status.h"

namespace icef {
namespace {

Result<int> ParsePositive(int v) {
  if (v <= 0) return Status::Error("value must be positive");
  return v;
}

Status UsesMacros(int v, int* out) {
  ICEF_ASSIGN_OR_RETURN(*out, ParsePositive(v));
  ICEF_RETURN_IF_ERROR(Status::Ok());
  return Status::Ok();
}

TEST(StatusTest, ResultCarriesValueOrError) {
  EXPECT_EQ(*ParsePositive(3), 3);
  Result<int> bad = ParsePositive(-1);
  EXPECT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(), "value must be positive");
  EXPECT_EQ(bad.status().WithContext("f.json").message(), "f.json: value must be positive");
  EXPECT_THROW(bad.value(), InternalError);
  int out = 0;
  EXPECT_TRUE(UsesMacros(5, &out).ok());
  EXPECT_EQ(out, 5);
  EXPECT_FALSE(UsesMacros(0, &out).ok());
}

TEST(StatusTest, CheckThrowsWithLocation) {
  try {
    ICEF_CHECK(1 + 1 == 3, "arithmetic");
    FAIL();
  } catch (const InternalError& e) {
    EXPECT_NE(std::string(e.what()).find("core_test.cc"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("arithmetic"), std::string::npos);
  }
}

TEST(RngTest, StreamsAreDeterministicAndIndependent) {
  Rng a(42, StreamId("rays"), 3, 7), b(42, StreamId("rays"), 3, 7), c(42, StreamId("rays"), 3, 8);
  std::vector<uint64_t> va, vb, vc;
  for (int i = 0; i < 16; ++i)
    va.push_back(a.NextU64()), vb.push_back(b.NextU64()), vc.push_back(c.NextU64());
  EXPECT_EQ(va, vb);
  EXPECT_NE(va, vc);
  Rng d(42, StreamId("rays"), 3, 7);
  d.Advance(5);
  EXPECT_EQ(d.NextU64(), va[5]);
}

TEST(RngTest, UniformMoments) {
  Rng r(1, StreamId("test"));
  double sum = 0, sum2 = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const double u = r.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum2 += u * u;
  }
  EXPECT_NEAR(sum / n, 0.5, 0.01);
  EXPECT_NEAR(sum2 / n - 0.25, 1.0 / 12.0, 0.01);
  double ns = 0;
  for (int i = 0; i < n; ++i) ns += r.Normal();
  EXPECT_NEAR(ns / n, 0.0, 0.02);
}

TEST(ParallelTest, RangesCoverEverythingOnceInThreadOrder) {
  Executor ex(3);
  std::vector<int> hits(1000, 0);
  std::vector<int64_t> begins(3, -1);
  ParallelFor(ex, 1000, [&](int64_t b, int64_t e, int t) {
    begins[t] = b;
    for (int64_t i = b; i < e; ++i) hits[i]++;
  });
  for (int h : hits) EXPECT_EQ(h, 1);
  EXPECT_EQ(begins[0], 0);
  EXPECT_LT(begins[1], begins[2]);
  std::vector<int> chunk_hits(777, 0);
  ParallelForChunks(ex, 777, 10, [&](int64_t b, int64_t e) {
    for (int64_t i = b; i < e; ++i) chunk_hits[i]++;
  });
  for (int h : chunk_hits) EXPECT_EQ(h, 1);
}

// Chunk sizes cut every batch into enough chunks for two threads to finish together (a batch of
// 4096 samples used to be one chunk on one thread), in whole granules, never above the maximum.
TEST(ParallelTest, BalancedChunksSplitSmallAndLargeBatches) {
  EXPECT_EQ(BalancedChunk(0, 128, 4096), 128);
  EXPECT_EQ(BalancedChunk(1, 128, 4096), 128);
  EXPECT_EQ(BalancedChunk(4096, 128, 4096), 256);  // 16 chunks, not 1
  EXPECT_EQ(BalancedChunk(1 << 20, 128, 4096), 4096);
  for (int64_t n : {100, 2048, 4097, 28600, 65536, 65537, 200000}) {
    const int64_t chunk = BalancedChunk(n, 128, 4096);
    EXPECT_EQ(chunk % 128, 0) << n;
    EXPECT_LE(chunk, 4096) << n;
    const int64_t chunks = (n + chunk - 1) / chunk;
    // At least half the target count after rounding up to granules; never more than the target.
    if (n >= kBalancedChunks * 128) {
      EXPECT_GE(chunks, kBalancedChunks / 2) << n;
    }
    if (n <= kBalancedChunks * 4096) {
      EXPECT_LE(chunks, kBalancedChunks) << n;
    }
  }
}

TEST(ParallelTest, ExceptionsReachTheCaller) {
  Executor ex(2);
  EXPECT_THROW(ParallelFor(ex, 10,
                           [](int64_t, int64_t, int t) {
                             if (t == 1) throw std::runtime_error("boom");
                           }),
               std::runtime_error);
}

TEST(ProgressTest, RendersRateAndEtaAndIsQuietWhenNotInteractive) {
  std::ostringstream out;
  ProgressBar bar("train", 100, out, /*interactive=*/false);
  const std::string line = bar.Render(50, 10.0, "loss 0.1");
  EXPECT_NE(line.find("50/100"), std::string::npos);
  EXPECT_NE(line.find("5.0/s"), std::string::npos);
  EXPECT_NE(line.find("ETA 10.0s"), std::string::npos);
  EXPECT_NE(line.find("loss 0.1"), std::string::npos);
  bar.Update(50, "x");
  EXPECT_TRUE(out.str().empty());
  bar.Finish("done");
  EXPECT_NE(out.str().find("done"), std::string::npos);
  EXPECT_EQ(ProgressBar::FormatDuration(125), "2m05s");
}

}  // namespace
}  // namespace icef
