// `icef demo`: the whole pipeline on built-in synthetic data. Synthesises a subject
// (icef synth), trains ICEF on its K training frames, renders a turntable and expression sweeps
// (neutral -> target -> beyond, into the extrapolation regime), reports held-out PSNR, and prints
// where every file is.
#pragma once

#include <filesystem>
#include <ostream>

#include "icef/core/status.h"

namespace icef {

struct DemoOptions {
  std::filesystem::path out = "demo_out";  // everything goes under this directory
  uint64_t identity_seed = 1;              // which synthetic person
  int k = 5;                               // training frames
  int resolution = 128;                    // image size
  double time_budget = 300;                // training wall-time cap, seconds (0 = none)
  int64_t steps = 1000;       // training steps: the bench's and the demo sheet's (docs/results/README.md)
  int turntable_frames = 24;  // views in the turntable
  int sweep_frames = 12;      // frames per expression sweep
  int threads = 0;            // worker threads (0 = all cores)
  bool quick = false;         // tiny settings (tests): 48 px, K = 3, 60 steps
};

Status RunDemo(const DemoOptions& options, std::ostream& out);

}  // namespace icef
