#include "icef/io/checkpoint.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include "icef/core/rng.h"

namespace icef {
namespace {

std::string RandomBytes(size_t n, uint64_t seed) {
  Rng rng(seed, StreamId("ckpt_test"));
  std::string s(n, '\0');
  for (auto& c : s) c = static_cast<char>(rng.NextU32());
  return s;
}

TEST(CheckpointTest, RoundTrip) {
  CheckpointWriter w;
  w.Add("config", "{\"a\": 1}");
  w.Add("params", RandomBytes(10000, 1));
  w.Add("empty", "");
  auto ck = Checkpoint::Parse(w.Serialize(), "mem");
  ASSERT_TRUE(ck.ok()) << ck.status().message();
  EXPECT_EQ(*ck->Section("config"), "{\"a\": 1}");
  EXPECT_EQ(*ck->Section("params"), RandomBytes(10000, 1));
  EXPECT_EQ(*ck->Section("empty"), "");
  EXPECT_FALSE(ck->Section("missing").ok());
  EXPECT_EQ(ck->SectionNames().size(), 3u);
}

TEST(CheckpointTest, EveryTruncationAndManyBitFlipsAreRefused) {
  CheckpointWriter w;
  w.Add("config", "{}");
  w.Add("params", RandomBytes(300, 2));
  const std::string good = w.Serialize();
  for (size_t n = 0; n < good.size(); ++n) {
    auto ck = Checkpoint::Parse(good.substr(0, n), "cut");
    ASSERT_FALSE(ck.ok()) << "accepted a checkpoint truncated to " << n << " bytes";
    EXPECT_NE(ck.status().message().find("cut"), std::string::npos);
  }
  Rng rng(3, StreamId("flip"));
  for (int trial = 0; trial < 500; ++trial) {
    std::string bad = good;
    const size_t pos = rng.Below(bad.size());
    bad[pos] = static_cast<char>(bad[pos] ^ (1u << rng.Below(8)));
    ASSERT_FALSE(Checkpoint::Parse(bad, "flip").ok()) << "accepted a bit flip at byte " << pos;
  }
}

TEST(CheckpointTest, FileRoundTripAndMissingFile) {
  const auto path =
      std::filesystem::temp_directory_path() / ("icef_ckpt_" + std::to_string(::getpid()) + ".bin");
  CheckpointWriter w;
  w.Add("x", "payload");
  ASSERT_TRUE(w.WriteAtomic(path).ok());
  auto ck = Checkpoint::Read(path);
  ASSERT_TRUE(ck.ok());
  EXPECT_EQ(*ck->Section("x"), "payload");
  std::filesystem::remove(path);
  EXPECT_FALSE(Checkpoint::Read(path).ok());
}

}  // namespace
}  // namespace icef
