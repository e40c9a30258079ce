#include "icef/nn/parameter_store.h"

#include <gtest/gtest.h>

#include <sstream>

namespace icef::nn {
namespace {

TEST(ParameterStoreTest, BlocksAreAlignedAndValuesSurviveRegistration) {
  ParameterStore store;
  const int a = store.Register("a", 5, 0);
  store.params(a)[4] = 7.0f;
  const int b = store.Register("b", 17, 1);
  EXPECT_EQ(store.block(a).offset, 0);
  EXPECT_EQ(store.block(b).offset, 16);
  EXPECT_EQ(store.size(), 48);
  EXPECT_EQ(store.params(a)[4], 7.0f);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(store.params(b).data()) % 64, 0u);
  EXPECT_EQ(store.FindBlock("b"), b);
  EXPECT_EQ(store.FindBlock("zz"), -1);
  EXPECT_THROW(store.Register("a", 3), InternalError);
}

TEST(ParameterStoreTest, RoundTripAndMismatchErrorsNameTheBlock) {
  ParameterStore store;
  store.Register("mlp", 10);
  store.Register("grid", 33, 1);
  for (int64_t i = 0; i < store.size(); ++i) store.params()[i] = 0.5f * i;
  std::stringstream buf;
  ASSERT_TRUE(store.Write(buf).ok());
  const std::string bytes = buf.str();

  ParameterStore same;
  same.Register("mlp", 10);
  same.Register("grid", 33, 1);
  std::istringstream in(bytes);
  ASSERT_TRUE(same.Read(in).ok());
  for (const ParamBlock& b : store.blocks())
    for (int64_t i = 0; i < b.size; ++i) EXPECT_EQ(same.params()[b.offset + i], store.params()[b.offset + i]);

  ParameterStore renamed;
  renamed.Register("mlp", 10);
  renamed.Register("hash", 33);
  std::istringstream in2(bytes);
  Status st = renamed.Read(in2);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("grid"), std::string::npos) << st.message();

  ParameterStore resized;
  resized.Register("mlp", 11);
  resized.Register("grid", 33);
  std::istringstream in3(bytes);
  st = resized.Read(in3);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("'mlp' has 10"), std::string::npos) << st.message();

  // A model with a block more (or less) than the file: the error names it.
  ParameterStore larger;
  larger.Register("mlp", 10);
  larger.Register("grid", 33, 1);
  larger.Register("cavity/colour", 3);
  std::istringstream in5(bytes);
  st = larger.Read(in5);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("'cavity/colour' is not in the file"), std::string::npos) << st.message();
  ParameterStore smaller;
  smaller.Register("mlp", 10);
  std::istringstream in6(bytes);
  st = smaller.Read(in6);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("'grid' in file is not in the model"), std::string::npos) << st.message();

  std::istringstream truncated(bytes.substr(0, bytes.size() - 8));
  st = same.Read(truncated);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("truncated"), std::string::npos) << st.message();

  std::string bad_version = bytes;
  bad_version[8] = 9;
  std::istringstream in4(bad_version);
  st = same.Read(in4);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("version"), std::string::npos) << st.message();
}

}  // namespace
}  // namespace icef::nn
