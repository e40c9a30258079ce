#include "icef/nn/adam.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

namespace icef::nn {
namespace {

TEST(AdamTest, MatchesReferenceUpdateAndSkipsZeroGradientsInSparseGroups) {
  ParameterStore store;
  const int dense = store.Register("mlp", 3, 0);
  const int sparse = store.Register("grid", 3, 1);
  AdamOptions o;
  o.groups = {AdamGroup{}, AdamGroup{}};
  o.groups[0].learning_rate = 1e-3;
  o.groups[0].weight_decay = 0.1;
  o.groups[1].learning_rate = 1e-2;
  o.groups[1].sparse = true;
  Adam adam(o, &store);
  for (int i = 0; i < 3; ++i) {
    store.params(dense)[i] = 1.0f + i;
    store.params(sparse)[i] = 1.0f + i;
  }
  // Reference in double.
  double p[3] = {1, 2, 3}, m[3] = {}, v[3] = {};
  Executor ex(2);
  for (int t = 1; t <= 3; ++t) {
    for (int i = 0; i < 3; ++i) {
      store.grads(dense)[i] = 0.5f * (i + 1) * t;
      store.grads(sparse)[i] = i == 1 ? 0.0f : 0.25f;
    }
    adam.Step(ex);
    for (int i = 0; i < 3; ++i) {
      const double g = 0.5 * (i + 1) * t;
      m[i] = 0.9 * m[i] + 0.1 * g;
      v[i] = 0.99 * v[i] + 0.01 * g * g;
      const double mh = m[i] / (1 - std::pow(0.9, t)), vh = v[i] / (1 - std::pow(0.99, t));
      p[i] -= 1e-3 * mh / (std::sqrt(vh) + 1e-15) + 1e-3 * 0.1 * p[i];
      EXPECT_NEAR(store.params(dense)[i], p[i], 1e-6);
      EXPECT_EQ(store.grads(dense)[i], 0.0f);  // consumed
    }
  }
  EXPECT_EQ(store.params(sparse)[1], 2.0f);                    // never had a gradient: untouched
  EXPECT_NEAR(store.params(sparse)[0], 1.0 - 3 * 1e-2, 1e-5);  // constant gradient: ~lr per step
  EXPECT_EQ(adam.step(), 3);
}

// A sparse group over a long table with a few entries hit per step: exactly those entries get
// Adam's update (bias-corrected with the optimiser's step count), and nothing else moves.
TEST(AdamTest, SparseGroupsUpdateExactlyTheEntriesWithAGradient) {
  ParameterStore store;
  const int table = store.Register("grid", 200, 0);
  AdamOptions o;
  o.groups = {AdamGroup{}};
  o.groups[0].learning_rate = 1e-2;
  o.groups[0].sparse = true;
  Adam adam(o, &store);
  for (int i = 0; i < 200; ++i) store.params(table)[i] = 0.01f * float(i);
  const std::vector<int> hit_first = {3, 17, 18, 199}, hit_second = {3, 120};
  double m[200] = {}, v[200] = {}, p[200];
  for (int i = 0; i < 200; ++i) p[i] = 0.01f * float(i);
  Executor ex(2);
  for (int t = 1; t <= 2; ++t) {
    const std::vector<int>& hit = t == 1 ? hit_first : hit_second;
    for (int i : hit) store.grads(table)[i] = 0.1f * float(i + 1);
    adam.Step(ex);
    for (int i : hit) {
      const double g = 0.1f * float(i + 1);
      m[i] = 0.9 * m[i] + 0.1 * g;
      v[i] = 0.99 * v[i] + 0.01 * g * g;
      p[i] -= 1e-2 * (m[i] / (1 - std::pow(0.9, t))) / (std::sqrt(v[i] / (1 - std::pow(0.99, t))) + 1e-15);
    }
    for (int i = 0; i < 200; ++i) {
      EXPECT_NEAR(store.params(table)[i], p[i], 1e-6) << "entry " << i << " step " << t;
      EXPECT_EQ(store.grads(table)[i], 0.0f);
    }
  }
  EXPECT_EQ(store.params(table)[50], 0.5f);  // never hit: bit-for-bit untouched
}

TEST(AdamTest, Schedules) {
  ParameterStore store;
  store.Register("a", 1);
  AdamOptions o;
  o.schedule = LrSchedule::kStep;
  o.decay_rate = 0.5;
  o.decay_steps = 10;
  Adam adam(o, &store);
  EXPECT_EQ(adam.ScheduleFactor(9), 1.0);
  EXPECT_EQ(adam.ScheduleFactor(10), 0.5);
  EXPECT_EQ(adam.ScheduleFactor(25), 0.25);
  o.schedule = LrSchedule::kExponential;
  adam.set_options(o);
  EXPECT_NEAR(adam.ScheduleFactor(5), std::sqrt(0.5), 1e-12);
  o.groups[0].beta1 = 1.0;
  EXPECT_FALSE(o.Validate().ok());
}

TEST(AdamTest, StateRoundTripsAndMismatchIsAnError) {
  ParameterStore store;
  store.Register("a", 5);
  Adam adam(AdamOptions{}, &store);
  for (int i = 0; i < 5; ++i) store.grads()[i] = 0.1f * (i + 1);
  adam.Step(Executor(1));
  std::stringstream buf;
  ASSERT_TRUE(adam.Write(buf).ok());
  const std::string bytes = buf.str();

  ParameterStore store2;
  store2.Register("a", 5);
  Adam adam2(AdamOptions{}, &store2);
  std::istringstream in(bytes);
  ASSERT_TRUE(adam2.Read(in).ok());
  EXPECT_EQ(adam2.step(), 1);
  // Same next step on both gives the same parameters.
  for (int i = 0; i < 5; ++i) store2.params()[i] = store.params()[i];
  for (int i = 0; i < 5; ++i) store.grads()[i] = store2.grads()[i] = 0.3f;
  adam.Step(Executor(1));
  adam2.Step(Executor(1));
  for (int i = 0; i < 5; ++i) EXPECT_EQ(store.params()[i], store2.params()[i]);

  ParameterStore other;
  other.Register("a", 20);
  Adam adam3(AdamOptions{}, &other);
  std::istringstream in2(bytes);
  const Status st = adam3.Read(in2);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("floats"), std::string::npos);
  std::istringstream garbage("nonsense");
  EXPECT_FALSE(adam3.Read(garbage).ok());
}

}  // namespace
}  // namespace icef::nn
