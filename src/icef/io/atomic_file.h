// Crash-safe file writes: the bytes go to a temporary file in the destination's directory, are
// flushed to disk, and the temporary is renamed over the destination. A crash or error at any
// point leaves either the old file or the new one, never a mix; the temporary is removed on error.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "icef/core/status.h"

namespace icef {

Status WriteFileAtomic(const std::filesystem::path& path, std::string_view bytes);

// Reads a whole file; the error names the file.
Result<std::string> ReadFile(const std::filesystem::path& path);

}  // namespace icef
