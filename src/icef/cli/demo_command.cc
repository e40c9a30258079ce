#include <iostream>
#include <memory>

#include "icef/app/demo_app.h"
#include "icef/cli/commands.h"
#include "icef/cli/validators.h"

namespace icef::cli {

CommandFn RegisterDemo(CLI::App& app) {
  app.description(
      "Run the whole pipeline on built-in synthetic data: synthesise a subject, train ICEF, render a "
      "turntable "
      "and expression sweeps, and print where the files are.");
  auto o = std::make_shared<DemoOptions>();
  app.add_option("--out", o->out, "Output directory")->capture_default_str();
  app.add_option("--identity-seed", o->identity_seed, "Which synthetic person")->capture_default_str();
  app.add_option("--k", o->k, "Training frames (3, 5 or 10)")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  app.add_option("--res", o->resolution, "Image resolution")
      ->capture_default_str()
      ->check(CLI::Range(16, 1024));
  app.add_option("--time-budget", o->time_budget,
                 "Training time cap, seconds (0 = none); training stops at --steps or here")
      ->capture_default_str()
      ->check(kNonNegative);
  app.add_option("--steps", o->steps,
                 "Training steps (1000: the bench's and the demo sheet's in docs/results/README.md)")
      ->capture_default_str()
      ->check(kPositive);
  app.add_option("--threads", o->threads, "Worker threads (0 = all cores)")
      ->capture_default_str()
      ->check(kNonNegative);
  app.add_flag("--quick", o->quick, "Tiny settings that finish in seconds (for tests)");
  return [o]() { return RunDemo(*o, std::cout); };
}

}  // namespace icef::cli
