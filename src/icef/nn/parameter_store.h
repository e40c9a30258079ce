// The parameter slab (tiny-cuda-nn style): every trainable float of a model lives in ONE
// contiguous, 64-byte aligned buffer, with a gradient buffer of the same layout beside it. Modules
// do not own parameters: at construction they Register() a named block (size, optimiser group)
// and later address it by the returned block index; one optimiser step then covers everything.
//
// Layout: blocks are laid out in registration order, each starting on a 16-float boundary
// (padding floats are zero and never trained). Registering a block re-allocates the slab, so
// pointers from params()/grads() are valid only until the next Register(); modules therefore keep
// the block index and fetch pointers at call time. Values already present survive a Register().
//
// Serialisation (checkpoints): Write() emits a versioned binary header
//   magic "ICEFPRM\0" (8 bytes), u32 version (=1), u32 block count,
//   per block: u32 name length, name bytes, i64 size, i32 group,
//   then i64 total floats and the parameter floats of each block in order (no padding),
// little-endian as the host. Read() requires the same block names, sizes and order and reports the
// first mismatch by name.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <span>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/nn/aligned.h"

namespace icef::nn {

struct ParamBlock {
  std::string name;    // unique, e.g. "static/hash_grid"
  int64_t offset = 0;  // first float in the slab
  int64_t size = 0;    // number of floats
  int group = 0;       // optimiser parameter group (learning rate etc.), see Adam
  std::string ToString() const;
};

class ParameterStore {
 public:
  ParameterStore() = default;
  ParameterStore(const ParameterStore&) = delete;
  ParameterStore& operator=(const ParameterStore&) = delete;

  // Adds a zero-initialised block; returns its index. Names must be unique (ICEF_CHECK).
  int Register(const std::string& name, int64_t size, int group = 0);

  int num_blocks() const { return static_cast<int>(blocks_.size()); }
  const ParamBlock& block(int index) const { return blocks_.at(index); }
  const std::vector<ParamBlock>& blocks() const { return blocks_; }
  // Index of the block with this name, or -1.
  int FindBlock(const std::string& name) const;

  // Total slab size in floats, padding included.
  int64_t size() const { return static_cast<int64_t>(params_.size()); }
  float* params() { return params_.data(); }
  const float* params() const { return params_.data(); }
  float* grads() { return grads_.data(); }
  const float* grads() const { return grads_.data(); }
  std::span<float> params(int block_index);
  std::span<const float> params(int block_index) const;
  std::span<float> grads(int block_index);
  std::span<const float> grads(int block_index) const;

  // Sets every gradient to zero (Adam::Step also zeroes the gradients it consumes).
  void ZeroGrads();

  Status Write(std::ostream& out) const;
  // Reads parameters written by Write(); block names/sizes/order must match this store.
  Status Read(std::istream& in);

  std::string ToString() const;

 private:
  std::vector<ParamBlock> blocks_;
  AlignedVector<float> params_;
  AlignedVector<float> grads_;
};

}  // namespace icef::nn
