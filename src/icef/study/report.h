// The bench report (docs/design.md §6): the aggregate and verdict of study/aggregate.h written as
// report.md + report.json (+ report.tex, study/report_latex.h), and plots of each metric against
// delta (one line per method, mean +- std over identities) drawn by gnuplot as PNG, SVG and PDF.
// Beside them, per K and method, the training-view fit (how well the models reproduce their own
// training views), and for validation benches a table of every run per identity.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "icef/study/aggregate.h"

namespace icef::eval {

// What the report says about the setup (copied into report.md / report.json).
struct ReportContext {
  std::string title = "ICEF benchmark";
  Json settings = Json::object();  // bench options, shown verbatim
  std::vector<std::string> notes;  // extra lines for report.md
  double wall_seconds = 0;         // whole bench (0: not shown)
  // What the identities are for, e.g. "test: never used for tuning" (empty: not shown).
  std::string identity_role;
  // The tiers' delta thresholds [near/moderate, moderate/far] (nullopt: not shown).
  std::optional<std::array<double, 2>> tier_thresholds;
  // A per-identity table (training-view fit, observed and far numbers of every run) and the worst
  // identity: for validation benches, where one identity that fails is the finding. Also on when
  // identity_role starts with "validation".
  bool per_identity = false;
  bool PerIdentity() const;
  // Run name -> a picture of its training views beside their truth, relative to the report's
  // directory (WriteReport makes one for each worst identity's lowest run; eval/training_view_sheet.h).
  std::map<std::string, std::string> run_sheets;
  // Where a run's directory (with its renders/) is when it is not DIR/runs/<name>: a merged bench's
  // runs stay in the directories that ran them (run name -> that directory's runs/<name>).
  std::map<std::string, std::filesystem::path> run_dirs;
};

std::string ReportMarkdown(const Aggregate& aggregate, const std::vector<RunRecord>& runs,
                           const ReportContext& context, const std::vector<std::string>& plots);
Json ReportJson(const Aggregate& aggregate, const std::vector<RunRecord>& runs, const ReportContext& context);

// Writes dir/plots/<metric>.{dat,gp,png,svg,pdf} (one panel per K, x = mean delta of each tier, one
// line per method with std error bars) for each metric with values. Returns the PNG paths
// relative to dir; when gnuplot is not installed, only the .dat/.gp files are written and
// `*note` says so.
// Whether gnuplot is on the PATH; RunGnuplot runs plot_dir/NAME.gp in plot_dir (its output to
// NAME.log, removed on success; the error names the script and the log).
bool HaveGnuplot();
Status RunGnuplot(const std::filesystem::path& plot_dir, const std::string& name);

Result<std::vector<std::string>> WritePlots(const std::filesystem::path& dir, const Aggregate& aggregate,
                                            std::string* note);

// Aggregates, plots and writes dir/report.md, dir/report.json and dir/report.tex (study/report_latex.h).
Status WriteReport(const std::filesystem::path& dir, const std::vector<RunRecord>& runs,
                   ReportContext context);

// Run records as stored under runs/<name>/metrics.json (metrics + a "run" object with
// identity_seed, k, method, train_steps, train_seconds, eval_seconds).
Json RunRecordJson(const RunRecord& record);
Result<RunRecord> ReadRunRecord(const std::filesystem::path& metrics_path);
// Every runs/*/metrics.json under dir, sorted by (identity, K, method order).
Result<std::vector<RunRecord>> ReadRunRecords(const std::filesystem::path& dir);

}  // namespace icef::eval
