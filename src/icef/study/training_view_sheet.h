// One picture of a bench run's training views beside their truth, for the report: the pairs that
// `icef eval` writes (DIR/runs/<run>/renders/fit_<frame>_vs_truth.png: truth left, render right),
// stacked top to bottom in frame order.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "icef/core/status.h"

namespace icef::eval {

// Writes DIR/worst_<run>_training_views.png from RUN_DIR/renders/fit_*_vs_truth.png (RUN_DIR:
// `run_dir`, by default DIR/runs/<run>; a merged bench passes the source directory that ran it,
// where the renders stay) and returns its name relative to DIR; nullopt when the run has no such
// renders. An unreadable render is an error naming the file.
Result<std::optional<std::string>> WriteTrainingViewSheet(const std::filesystem::path& dir,
                                                          const std::string& run,
                                                          const std::filesystem::path& run_dir = {});

}  // namespace icef::eval
