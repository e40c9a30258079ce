#include "icef/core/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace icef {

ProgressBar::ProgressBar(std::string label, int64_t total, std::ostream& out, bool interactive)
    : label_(std::move(label)),
      total_(std::max<int64_t>(total, 1)),
      out_(out),
      interactive_(interactive),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_ - std::chrono::seconds(1)) {}

ProgressBar::~ProgressBar() {
  if (interactive_ && !finished_) out_ << "\n" << std::flush;
}

std::string ProgressBar::FormatDuration(double s) {
  char buf[32];
  if (!(s >= 0) || s > 1e7) return "--";
  if (s >= 3600) {
    std::snprintf(buf, sizeof buf, "%dh%02dm", static_cast<int>(s / 3600), static_cast<int>(s / 60) % 60);
  } else if (s >= 60) {
    std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(s / 60), static_cast<int>(s) % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%.1fs", s);
  }
  return buf;
}

std::string ProgressBar::Render(int64_t done, double elapsed, const std::string& status) const {
  const double frac = std::clamp(static_cast<double>(done) / total_, 0.0, 1.0);
  constexpr int kWidth = 24;
  const int filled = static_cast<int>(frac * kWidth);
  std::string bar(filled, '#');
  bar.resize(kWidth, '.');
  const double rate = elapsed > 0 ? done / elapsed : 0.0;
  const double eta = rate > 0 ? (total_ - done) / rate : -1.0;
  char buf[256];
  std::snprintf(buf, sizeof buf, "%s [%s] %lld/%lld %5.1f%% %.1f/s ETA %s", label_.c_str(), bar.c_str(),
                static_cast<long long>(done), static_cast<long long>(total_), 100.0 * frac, rate,
                done >= total_ ? "0s" : FormatDuration(eta).c_str());
  std::string line = buf;
  if (!status.empty()) line += "  " + status;
  return line;
}

void ProgressBar::Update(int64_t done, const std::string& status) {
  done_ = done;
  if (!interactive_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(100) && done < total_) return;
  last_draw_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  out_ << "\r\033[K" << Render(done, elapsed, status) << std::flush;
}

void ProgressBar::Finish(const std::string& status) {
  if (finished_) return;
  finished_ = true;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (interactive_) out_ << "\r\033[K";
  out_ << Render(done_, elapsed, status) << " (" << FormatDuration(elapsed) << ")\n" << std::flush;
}

bool StdoutIsTerminal() {
  if (!isatty(STDOUT_FILENO)) return false;
  const char* term = std::getenv("TERM");
  return !(term && std::strcmp(term, "dumb") == 0);
}

}  // namespace icef
