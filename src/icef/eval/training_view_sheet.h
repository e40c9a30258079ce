// One picture of a bench run's training views beside their truth, for the report: the pairs that
// `icef eval` writes (DIR/runs/<run>/renders/fit_<frame>_vs_truth.png: truth left, render right),
// stacked top to bottom in frame order.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "icef/core/status.h"

namespace icef::eval {

// Writes DIR/worst_<run>_training_views.png from DIR/runs/<run>/renders/fit_*_vs_truth.png and
// returns its name relative to DIR; nullopt when the run has no such renders (a merged bench keeps
// its renders in the source directories). An unreadable render is an error naming the file.
Result<std::optional<std::string>> WriteTrainingViewSheet(const std::filesystem::path& dir, const std::string& run);

}  // namespace icef::eval
