// A progress bar for long loops: done/total, rate, ETA and a caller-supplied status text (e.g.
// "loss 0.012 psnr 27.1"). Redraws in place at most ~10 times a second when the stream is a
// terminal; otherwise it stays quiet until Finish(), which prints one summary line.
#pragma once

#include <chrono>
#include <cstdint>
#include <ostream>
#include <string>

namespace icef {

class ProgressBar {
 public:
  // interactive: redraw in place (pass IsTerminal(stdout) from the CLI).
  ProgressBar(std::string label, int64_t total, std::ostream& out, bool interactive);
  ~ProgressBar();

  void Update(int64_t done, const std::string& status = "");
  // Prints the final line (always, interactive or not). Idempotent.
  void Finish(const std::string& status = "");

  // Formats seconds as "1h02m", "3m05s" or "12.3s".
  static std::string FormatDuration(double seconds);
  // The text of one bar line, without carriage return; exposed for tests.
  std::string Render(int64_t done, double elapsed_seconds, const std::string& status) const;

 private:
  std::string label_;
  int64_t total_;
  std::ostream& out_;
  bool interactive_;
  bool finished_ = false;
  int64_t done_ = 0;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

// True when stdout is a terminal (and TERM is not "dumb").
bool StdoutIsTerminal();

}  // namespace icef
