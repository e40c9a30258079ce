#include "icef/nn/reference_model.h"

#include <gtest/gtest.h>

#include <cstring>
#include <sstream>

namespace icef::nn {
namespace {

bool SameBits(const float* a, const float* b, int64_t n) { return std::memcmp(a, b, n * sizeof(float)) == 0; }

// Two runs with the same seed and 2 threads give bit-identical gradients, parameters and outputs.
TEST(DeterminismTest, TwoThreadRunsAreBitIdentical) {
  const ReferenceBatch batch = MakeReferenceBatch(96, 32, 7);
  const Executor ex(2);
  ReferenceModel a(42), b(42);
  for (int step = 0; step < 2; ++step) {
    const double la = a.ForwardBackward(ex, batch), lb = b.ForwardBackward(ex, batch);
    EXPECT_EQ(la, lb);
    ASSERT_TRUE(SameBits(a.store().grads(), b.store().grads(), a.store().size())) << "step " << step;
    a.OptimizerStep(ex);
    b.OptimizerStep(ex);
    ASSERT_TRUE(SameBits(a.store().params(), b.store().params(), a.store().size())) << "step " << step;
  }
  std::vector<float> oa(batch.num_samples() * 4), ob(oa.size());
  a.Infer(ex, batch, oa.data());
  b.Infer(ex, batch, ob.data());
  EXPECT_TRUE(SameBits(oa.data(), ob.data(), static_cast<int64_t>(oa.size())));
}

// Work is split into fixed chunks with per-chunk accumulators, so even the thread count does not
// change a single bit.
TEST(DeterminismTest, ThreadCountDoesNotChangeResults) {
  const ReferenceBatch batch = MakeReferenceBatch(300, 32, 8);  // 9600 samples: a partial chunk
  ReferenceModel one(3), three(3);
  one.TrainStep(Executor(1), batch);
  three.TrainStep(Executor(3), batch);
  const double l1 = one.ForwardBackward(Executor(1), batch), l3 = three.ForwardBackward(Executor(3), batch);
  EXPECT_EQ(l1, l3);
  EXPECT_TRUE(SameBits(one.store().grads(), three.store().grads(), one.store().size()));
  EXPECT_TRUE(SameBits(one.store().params(), three.store().params(), one.store().size()));
}

TEST(ReferenceModelTest, GradientsReachEveryModuleAndTrainingReducesTheLoss) {
  const ReferenceBatch batch = MakeReferenceBatch(64, 32, 3);
  const Executor ex(2);
  ReferenceModel m(5);
  m.ForwardBackward(ex, batch);
  for (const ParamBlock& blk : m.store().blocks()) {
    double norm = 0;
    for (float g : m.store().grads(m.store().FindBlock(blk.name))) norm += double(g) * g;
    EXPECT_GT(norm, 0.0) << blk.name;
  }
  m.OptimizerStep(ex);
  const double first = m.ForwardBackward(ex, batch);
  m.OptimizerStep(ex);
  double last = first;
  for (int i = 0; i < 20; ++i) last = m.TrainStep(ex, batch);
  EXPECT_LT(last, 0.9 * first);
  // Training and inference forward passes agree.
  std::vector<float> out(batch.num_samples() * 4);
  m.Infer(ex, batch, out.data());
  for (float v : out) ASSERT_TRUE(std::isfinite(v));
}

TEST(ReferenceModelTest, CheckpointSectionsRoundTrip) {
  ReferenceModel m(1);
  std::stringstream buf;
  ASSERT_TRUE(m.store().Write(buf).ok());
  ReferenceModel other(2);
  ASSERT_FALSE(SameBits(m.store().params(), other.store().params(), m.store().size()));
  ASSERT_TRUE(other.store().Read(buf).ok());
  EXPECT_TRUE(SameBits(m.store().params(), other.store().params(), m.store().size()));
}

}  // namespace
}  // namespace icef::nn
