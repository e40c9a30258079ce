// The report of `icef bench --real` (docs/design.md §9): per source, per K and method, the means of
// eval/real_protocol.h's measures over the held-out real frames, as report.md, report.json,
// report.tex (booktabs) and plots of face PSNR and real_expr_gain against K (gnuplot: PNG, SVG,
// PDF), with each source's worst held-out frames beside their photos (worst_<source>.png: photo,
// render at the tracked expression, render at the nearest training expression).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/eval/real_protocol.h"
#include "icef/io/json_util.h"

namespace icef::eval {

// One real-media run: a source, K training frames, a method.
struct RealRunRecord {
  std::string source;  // the source's name (its directory under sources/)
  int k = 0;
  std::string method;
  RealEvalResult metrics;
  int64_t train_steps = 0;
  double train_seconds = 0;
  std::filesystem::path dataset;  // the run's dataset (photos), for the worst-frame sheets
  std::filesystem::path run_dir;  // where its renders are
  // "<source>_k<K>_<method>": the directory name under runs/.
  std::string Name() const;
  Json ToJson() const;
  static Result<RealRunRecord> FromJson(const Json& json, const std::string& where);
};

// What the report says about each source: where it came from and how it was tracked.
struct RealSourceInfo {
  std::string name;
  std::string origin;              // the path or description given
  int pool_train = 0;              // training frames available
  int test = 0;                    // held-out frames
  std::vector<std::string> notes;  // e.g. "K = 10 left out: only 6 training frames"
};

struct RealReportContext {
  std::vector<RealSourceInfo> sources;
  std::string settings;  // one line: resolution, steps, methods
};

// The Markdown table of the runs: one row per (source, K, method).
std::string RealReportMarkdown(const std::vector<RealRunRecord>& runs, const RealReportContext& context,
                               const std::vector<std::string>& images);
std::string RealReportLatex(const std::vector<RealRunRecord>& runs, const RealReportContext& context);

// The worst `count` held-out frames of a run by face PSNR, each as a row of photo | render |
// nearest-expression render (labelled); nullopt-like empty image when no renders were written.
Result<Image> WorstFramesSheet(const RealRunRecord& run, int count);

// Writes report.md, report.json, report.tex, plots/ and the sheets into dir.
Status WriteRealReport(const std::filesystem::path& dir, const std::vector<RealRunRecord>& runs,
                       const RealReportContext& context);

}  // namespace icef::eval
