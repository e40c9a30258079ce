// Fully-connected network without biases (tiny-cuda-nn style): hidden layers ReLU, output layer
// none / relu / sigmoid / exp. Parameters live in a ParameterStore block; see mlp_kernels.h for the
// weight layout (layer l stored transposed, Wt_l [w_l, w_{l+1}]).
//
// Initialisation: layers followed by ReLU use Kaiming-uniform, U(-sqrt(6/fan_in), +sqrt(6/fan_in));
// the output layer uses Xavier-uniform, U(-sqrt(6/(fan_in+fan_out)), +...), times
// output_init_scale (e.g. 1e-3 to start a residual deformation near the identity). Draws come
// from Rng(seed, "mlp_init", block index, weight index): independent of threads.
//
// Threading: samples are split into chunks of MlpChunkSize(n) samples handed to threads
// dynamically (ParallelForChunks), each chunk into tiles of kMlpTile samples that stay in L1/L2
// through all layers. Weight gradients accumulate per chunk and are added to the slab in chunk
// order; the chunk size depends on n alone, so results are bit-identical for any thread count and
// scheduling. Nothing is allocated per
// batch once the MlpContext has grown to the batch size.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/nn/activation.h"
#include "icef/nn/aligned.h"
#include "icef/nn/mlp_kernels.h"
#include "icef/nn/parameter_store.h"

namespace icef::nn {

// Samples per tile in the threaded Mlp entry points.
inline constexpr int64_t kMlpTile = 128;
// The most samples per dynamically scheduled work chunk (a multiple of kMlpTile); weight
// gradients accumulate per chunk and are reduced in chunk order.
inline constexpr int64_t kMlpChunk = 4096;
// Samples per chunk for a batch of n (core/parallel.h's BalancedChunk in whole tiles).
constexpr int64_t MlpChunkSize(int64_t n) { return BalancedChunk(n, kMlpTile, kMlpChunk); }

struct MlpOptions {
  // Layer widths: input, hidden..., output (at least input and output).
  std::vector<int> widths = {32, 64, 16};
  // Activation of the output layer (hidden layers are ReLU).
  Activation output_activation = Activation::kNone;
  // Multiplies the initial output-layer weights.
  float output_init_scale = 1.0f;
  // Forward passes without a backward pass (inference) multiply in BF16 with FP32 sums
  // (nn/gemm_bf16.h) when the build has the kernel.
  bool bf16_inference = false;
  // Training passes too: the forward pass kept for the backward pass, the backward data products
  // and the weight gradients multiply in BF16 with FP32 sums (the weights, their gradients and
  // Adam stay FP32); products whose output width is not a multiple of 16 stay FP32.
  bool bf16_training = false;

  Status Validate() const;
  std::string ToString() const;
};

// Per-batch state: hidden activations kept for Backward, per-thread scratch and gradients.
// Reuse one context across batches; it grows to the largest batch and never shrinks.
struct MlpContext {
  int64_t n = 0;                      // samples of the last Forward with keep_for_backward
  int num_threads = 0;                // thread count of that Forward (informational)
  AlignedVector<float> hidden;        // [n * hidden_per_sample], tile-major (see Mlp::Forward)
  AlignedVector<float> scratch;       // per thread: tile-sized work buffers
  AlignedVector<float> weight_grads;  // per chunk: [num_params] gradient accumulators
  AlignedVector<float> w_transposed;  // untransposed weights for the backward pass
  MlpBf16Weights bf16;                // the weights packed for BF16 products
  MlpBf16Weights bf16_transposed;     // w_transposed packed for BF16 backward products
};

class Mlp {
 public:
  // Registers block `name` (group `group`) in *store; the store must outlive the Mlp.
  Mlp(const MlpOptions& options, ParameterStore* store, const std::string& name, int group = 0);

  // Writes initial weights into the slab (see the header comment).
  void Initialize(uint64_t seed);

  const MlpOptions& options() const { return options_; }
  const MlpShape& shape() const { return shape_; }
  int input_dims() const { return shape_.input_dims(); }
  int output_dims() const { return shape_.output_dims(); }
  int64_t num_params() const { return shape_.num_params(); }
  int block_index() const { return block_; }
  const float* weights() const { return store_->params(block_).data(); }
  float* weights() { return store_->params(block_).data(); }
  float* weight_grads() { return store_->grads(block_).data(); }

  // x [n, input_dims] -> y [n, output_dims]. With keep_for_backward the hidden activations of
  // all n samples are kept in ctx (n * hidden_per_sample floats); otherwise ctx only lends
  // tile scratch (inference).
  void Forward(const Executor& executor, int64_t n, const float* x, float* y, MlpContext* ctx,
               bool keep_for_backward = true) const;

  // After Forward(keep_for_backward) on the same n and x: dy [n, output_dims] ->
  // accumulates d loss / d weights into the store's gradient; writes dx [n, input_dims] unless
  // dx is null.
  void Backward(const Executor& executor, int64_t n, const float* x, const float* y, const float* dy,
                MlpContext* ctx, float* dx);

  // y = f(x) and jy = J_f(x) · v with v [n, slice_dims] on input columns
  // [slice_begin, slice_begin + slice_dims); y, jy [n, output_dims].
  void Jvp(const Executor& executor, int64_t n, const float* x, int slice_begin, int slice_dims,
           const float* v, float* y, float* jy, MlpContext* ctx) const;

  std::string ToString() const;

 private:
  MlpOptions options_;
  MlpShape shape_;
  ParameterStore* store_;
  int block_;
};

}  // namespace icef::nn
