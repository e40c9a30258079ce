// Crash-safe file writes: the bytes go to a temporary file in the destination's directory, are
// flushed to disk, and the temporary is renamed over the destination. A crash or error at any
// point leaves either the old file or the new one, never a mix; the temporary is removed on error.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

#include "icef/core/status.h"

namespace icef {

Status WriteFileAtomic(const std::filesystem::path& path, std::string_view bytes);

// A new directory, all or nothing: `fill` writes its contents into a temporary sibling directory,
// which is then renamed to `dir`. `dir` must not exist or be an empty directory (nothing already
// there is touched otherwise); on any error the temporary is removed and `dir` is left as it was.
Status CreateDirectoryAtomic(const std::filesystem::path& dir,
                             const std::function<Status(const std::filesystem::path& tmp)>& fill);

// Reads a whole file; the error names the file.
Result<std::string> ReadFile(const std::filesystem::path& path);

}  // namespace icef
