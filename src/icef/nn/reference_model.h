// docs/design.md §7's reference configuration composed from the nn pieces and fused per tile: the
// workload of the benchmarks (bench/reference_bench.cc) and of the determinism test. It is not a
// renderer: a simple stand-in loss replaces volume rendering.
//
// Per sample (world frame, aabb [-1,1]^3):
//   g      = DeformMlp([freq6(x) (39), beta (16)])            55 -> 64 -> 64 -> 64 -> 3 (linear)
//   x_c    = x + g;  p = (x_c + 1) / 2                          normalised canonical, [0,1]^3
//   f      = HashGrid(p)                                        L=16, F=2, T=2^19, 16 .. 1024
//   h      = DensityMlp(f)                                      32 -> 64 -> 16;  sigma = exp(h_0)
//   rgb    = ColourMlp([h (16), SH4(d) (16)])                   32 -> 64 -> 64 -> 3 (sigmoid)
//   loss   = mean_s ( |rgb - target|^2 + 0.01 sigma )
// Training step = forward + backward (parameter gradients of all four modules, through the
// canonical position into the deformation net) + Adam (lr 1e-2 grid [sparse], 1e-3 MLPs, betas
// 0.9/0.99, eps 1e-15).
//
// Execution: pass 1 splits samples into fixed chunks of kReferenceChunk samples, handed to threads
// dynamically; a chunk runs tiles of kReferenceTile samples through every stage forward and
// backward while activations stay in L1/L2, accumulating MLP weight gradients in its own buffer;
// the buffers are reduced in chunk order. Pass 2 scatters the hash-table gradients one level per
// work item (each level sees the samples in index order). Pass 3 is Adam (elementwise). The
// result is bit-identical for any thread count and any scheduling.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "icef/core/parallel.h"
#include "icef/nn/adam.h"
#include "icef/nn/aligned.h"
#include "icef/nn/frequency_mlp.h"
#include "icef/nn/hash_grid.h"
#include "icef/nn/mlp.h"
#include "icef/nn/parameter_store.h"
#include "icef/nn/scratch_pool.h"
#include "icef/nn/sh_encoding.h"

namespace icef::nn {

inline constexpr int64_t kReferenceTile = 128;
// Samples per work chunk: chunks are handed to threads dynamically (load balancing on a shared
// machine); each chunk has its own MLP-gradient accumulator, reduced in chunk order.
inline constexpr int64_t kReferenceChunk = 4096;
inline constexpr int kReferenceExpressionDims = 16;

// A synthetic batch: rays through the aabb [-1,1]^3 from a sphere of radius 3, samples evenly
// spaced inside the box; per-ray expression vectors; random targets.
struct ReferenceBatch {
  int64_t num_rays = 0;
  int samples_per_ray = 0;
  int64_t num_samples() const { return num_rays * samples_per_ray; }
  AlignedVector<float> positions;   // [N, 3] world frame
  AlignedVector<float> directions;  // [N, 3] unit, world frame
  AlignedVector<float> betas;       // [num_rays, 16]
  AlignedVector<float> targets;     // [N, 3] in [0, 1]
};

ReferenceBatch MakeReferenceBatch(int64_t num_rays, int samples_per_ray, uint64_t seed);

// Accumulated wall time per phase (seconds) over the steps run so far.
struct ReferenceTimings {
  double fused_tiles = 0;   // pass 1: forward + backward of all modules per tile
  double grid_scatter = 0;  // pass 2: hash-table gradients
  double reduce = 0;        // per-thread MLP gradients into the slab
  double adam = 0;          // optimiser
  int64_t steps = 0;
  std::string ToString() const;
};

class ReferenceModel {
 public:
  // Builds and initialises every module and the optimiser (deterministic in seed).
  explicit ReferenceModel(uint64_t seed);
  ~ReferenceModel();

  // Forward + backward; leaves the gradients in store(); returns the loss.
  double ForwardBackward(const Executor& executor, const ReferenceBatch& batch);
  // Adam step (consumes the gradients).
  void OptimizerStep(const Executor& executor);
  double TrainStep(const Executor& executor, const ReferenceBatch& batch) {
    const double loss = ForwardBackward(executor, batch);
    OptimizerStep(executor);
    return loss;
  }
  // rgb_sigma [N, 4]: rgb then sigma per sample.
  void Infer(const Executor& executor, const ReferenceBatch& batch, float* rgb_sigma);

  ParameterStore& store() { return store_; }
  const HashGridEncoding& grid() const { return grid_; }
  const FrequencyMlp& deform() const { return deform_; }
  const Mlp& density() const { return density_; }
  const Mlp& colour() const { return colour_; }
  // Forward multiply-adds per sample in the three MLPs.
  int64_t MlpMacsPerSample() const;
  const ReferenceTimings& timings() const { return timings_; }

 private:
  struct ThreadBuffers;
  void EnsureBuffers(int64_t n);
  void ForwardTile(ThreadBuffers& b, const ReferenceBatch& batch, int64_t s0, int64_t m, bool train,
                   float* rgb_sigma);
  // Accumulates MLP weight gradients into dw (deformation, density, colour blocks back to back).
  double BackwardTile(ThreadBuffers& b, const ReferenceBatch& batch, int64_t s0, int64_t m, float* dw);

  ParameterStore store_;
  HashGridEncoding grid_;
  FrequencyMlp deform_;
  Mlp density_;
  Mlp colour_;
  ShEncoding sh_;
  std::unique_ptr<Adam> adam_;
  std::unique_ptr<ScratchPool<ThreadBuffers>> pool_;
  AlignedVector<float> chunk_grads_;  // [num_chunks, MLP params]
  std::vector<double> chunk_loss_;
  AlignedVector<float> canonical_;   // [N, 3] normalised canonical positions (pass 2 input)
  AlignedVector<float> d_features_;  // [16][N][2] d loss / d grid features, level-major (pass 2)
  AlignedVector<float> wt_deform_, wt_density_, wt_colour_;  // untransposed weights (backward)
  ReferenceTimings timings_;
};

}  // namespace icef::nn
