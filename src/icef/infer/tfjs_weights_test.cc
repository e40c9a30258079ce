#include "icef/infer/tfjs_weights.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "icef/infer/cnn_test_util.h"

namespace icef::infer {
namespace {

namespace fs = std::filesystem;

TEST(TfjsWeightsTest, DecodesFloatAndQuantisedTensors) {
  const fs::path dir = fs::path(::testing::TempDir()) / "icef_tfjs_ok";
  const Result<TensorMap> tensors = ReadTfjsWeights(testing::WriteTinyTfjs(dir));
  ASSERT_TRUE(tensors.ok()) << tensors.status().message();
  ASSERT_EQ(tensors->size(), 2u);
  EXPECT_EQ(tensors->at("a").shape, (std::vector<int>{2, 2}));
  EXPECT_EQ(tensors->at("a").values, (std::vector<float>{1.f, -2.f, 3.5f, 0.25f}));
  EXPECT_EQ(tensors->at("b").values, (std::vector<float>{-1.f, 1.f, 126.5f}));
}

TEST(TfjsWeightsTest, TruncatedShardIsAnErrorNamingTheTensor) {
  const fs::path dir = fs::path(::testing::TempDir()) / "icef_tfjs_short";
  const Result<TensorMap> tensors = ReadTfjsWeights(testing::WriteTinyTfjs(dir, 1));
  ASSERT_FALSE(tensors.ok());
  EXPECT_NE(tensors.status().message().find("weights[1]"), std::string::npos) << tensors.status().message();
}

TEST(TfjsWeightsTest, MissingManifestIsAnErrorNamingTheFile) {
  const fs::path path = fs::path(::testing::TempDir()) / "icef_tfjs_nowhere" / "m.json";
  const Result<TensorMap> tensors = ReadTfjsWeights(path);
  ASSERT_FALSE(tensors.ok());
  EXPECT_NE(tensors.status().message().find("m.json"), std::string::npos) << tensors.status().message();
}

}  // namespace
}  // namespace icef::infer
