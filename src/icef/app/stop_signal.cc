#include "icef/app/stop_signal.h"

#include <unistd.h>

#include <csignal>
#include <cstdlib>

namespace icef {

namespace {
std::atomic<bool> g_stop{false};  // written only by the signal handler

void OnSignal(int signal) {
  if (g_stop.exchange(true)) std::_Exit(128 + signal);
  const char msg[] = "\nicef: stopping after this step (writing a checkpoint); press Ctrl-C again to abort\n";
  (void)!::write(STDERR_FILENO, msg, sizeof msg - 1);
}
}  // namespace

const std::atomic<bool>* InstallStopHandlers() {
  struct sigaction action {};
  action.sa_handler = OnSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  return &g_stop;
}

}  // namespace icef
