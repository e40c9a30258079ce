// `icef bench --real SOURCE... --out DIR` (docs/design.md §9): the self-reenactment protocol on real
// media. Each source (a video, a folder of photos, or a dataset `icef track` made) is tracked once
// into OUT/sources/<name>/tracked (its held-out frames fixed: a video's spread over its time, a photo
// folder's last photos); for each K, OUT/sources/<name>/k<K> holds the K training frames that cover
// head pose and expression best (data/frame_coverage.h, nested: the 3 are among the 5) and all
// held-out frames; each method trains on it and is scored on the held-out photos
// (eval/real_protocol.h) into OUT/runs/<source>_k<K>_<method>/metrics.json; then the report
// (study/real_report.h). Resumable: a tracked source, a K's dataset and a run's metrics.json that
// exist are kept.
#pragma once

#include <cstdint>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "icef/core/status.h"

namespace icef {

struct RealBenchOptions {
  std::vector<std::filesystem::path> sources;  // videos, photo folders, tracked datasets
  std::filesystem::path out_dir;               // created; sources/, runs/, report.*
  std::vector<int> ks = {3, 5, 10};            // training-frame counts (a source with fewer frames skips a K)
  std::vector<std::string> methods = {"icef-prior", "icef"};
  int test_frames = 4;    // held-out frames per source (a photo folder keeps >= min K to train)
  int video_frames = 24;  // frames tracked from a video (spread over it)
  int resolution = 256;   // tracked image side, pixels
  std::string face_model = "procedural";  // the tracker's face model (track::TrackFaceModel's names)
  int64_t steps = 1000;                   // training steps per run
  double time_budget_seconds = 0;         // training wall-clock cap per run (0 = none)
  std::string config_path;                // base run config ("" = defaults)
  std::vector<std::string> overrides;     // "section.key=value" for every run
  int threads = 0;                        // worker threads (0 = all cores)
  std::string faceid_model_dir;           // "" = default lookup
  std::string lpips_weights;              // "" = LPIPS unavailable
  bool keep_models = false;               // keep runs/<name>/model/
  bool interactive = false;               // progress bars redraw in place

  // Tiny settings for tests: K = 3, 2 held-out frames, 64 px, 20 steps, a tiny model.
  void ApplyQuick();
  Status Validate() const;
  std::string ToString() const;
};

Status RunRealBench(const RealBenchOptions& options, std::ostream& log);

}  // namespace icef
