// SIGINT / SIGTERM during long jobs: the first signal sets a flag that the job polls (training then
// writes a final checkpoint and exits cleanly); a second signal ends the process at once.
#pragma once

#include <atomic>

namespace icef {

// Installs the handlers (idempotent) and returns the flag they set.
const std::atomic<bool>* InstallStopHandlers();

}  // namespace icef
