// icef: the command-line tool. Parses the subcommand, runs it, maps errors to exit codes:
// 0 success, 1 user error (message on stderr), 2 internal error.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "icef/cli/commands.h"

namespace {

CLI::App* FindSubcommand(CLI::App* command, const std::string& name) {
  const std::vector<CLI::App*> found =
      command->get_subcommands([&](CLI::App* sub) { return sub->get_name() == name; });
  return found.empty() ? nullptr : found.front();
}

// The subcommand the command line names (the words right after `icef`: `train`, `bench merge`) and
// the index of the first argument after them.
std::pair<CLI::App*, int> NamedCommand(CLI::App& app, int argc, char** argv) {
  CLI::App* command = &app;
  int i = 1;
  for (; i < argc; ++i) {
    CLI::App* sub = FindSubcommand(command, argv[i]);
    if (sub == nullptr) break;
    command = sub;
  }
  return {command, i};
}

// The first option after the subcommand that it does not define, or "" (CLI11 reports a missing
// required argument first, which hides a misspelt option). Values that are numbers (`--yaw -30`)
// and everything after `--` are not options.
std::string UnknownOption(CLI::App* command, int first, int argc, char** argv) {
  for (int i = first; i < argc; ++i) {
    const std::string token = argv[i];
    if (token == "--") break;
    if (token.size() < 2 || token[0] != '-') continue;
    char* end = nullptr;
    std::strtod(token.c_str(), &end);
    if (end != nullptr && *end == '\0') continue;  // a negative number
    const std::string name = token.substr(0, token.find('='));
    const bool is_long = name.rfind("--", 0) == 0;
    if (!is_long && name.size() != 2) continue;  // grouped short flags: left to CLI11
    if (command->get_option_no_throw(name) == nullptr) return name;
  }
  return "";
}

using Register = icef::cli::CommandFn (*)(CLI::App&);
struct Command {
  const char* name;
  const char* description;
  Register add;
};
const Command kCommands[] = {
    {"demo", "Run the built-in demo end to end", icef::cli::RegisterDemo},
    {"info", "Summarise and validate a dataset", icef::cli::RegisterInfo},
    {"synth", "Render a synthetic ground-truth dataset of a procedural head", icef::cli::RegisterSynth},
    {"sheet", "Tile a dataset into a labelled contact sheet PNG", icef::cli::RegisterSheet},
    {"import", "Convert a NerFace / instant-ngp dataset into our format", icef::cli::RegisterImport},
    {"train", "Train a model (icef or a baseline) on a dataset", icef::cli::RegisterTrain},
    {"render", "Render a trained model: views, expressions, sweeps, turntables", icef::cli::RegisterRender},
    {"export", "Export a trained avatar as a GLB with ARKit-named morph targets", icef::cli::RegisterExport},
    {"view", "The avatar in the browser: a folder with the GLB and a three.js viewer, optionally served",
     icef::cli::RegisterView},
    {"config", "Print the resolved run config, or document every key (--markdown)",
     icef::cli::RegisterConfig},
    {"mask", "Show the expression-region mask (overlay + volume slices)", icef::cli::RegisterMask},
    {"landmarks", "Detect 68 face landmarks (dlib) and write them into a dataset",
     icef::cli::RegisterLandmarks},
    {"track", "Turn photos of one person into a dataset: landmarks, face-model fit, crops, masks",
     icef::cli::RegisterTrack},
    {"faceid", "Face-identity descriptors of photos and their pairwise distances", icef::cli::RegisterFaceId},
    {"eval", "Evaluate a trained model: PSNR, SSIM, LPIPS, identity consistency per tier",
     icef::cli::RegisterEval},
    {"bench", "Run the benchmark (synthesise, train, evaluate every method) and write the report",
     icef::cli::RegisterBench},
};

// The exit code for a command line that names no subcommand, an unknown one or an unknown option,
// with its message on stderr; nullopt for one CLI11 should parse.
std::optional<int> RejectCommandLine(CLI::App& app, int argc, char** argv) {
  // Bare `icef`: the overview of the subcommands rather than CLI11's one-line complaint.
  if (argc < 2) {
    std::cerr << app.help();
    return 1;
  }
  // A first word that is no subcommand: name it (CLI11 would only say that a subcommand is required).
  const std::string first = argv[1];
  const bool known = std::any_of(std::begin(kCommands), std::end(kCommands),
                                 [&](const Command& command) { return first == command.name; });
  if (first[0] != '-' && !known) {
    std::cerr << "icef: unknown subcommand '" << first << "'; the subcommands are:";
    for (const Command& command : kCommands) std::cerr << " " << command.name;
    std::cerr << " (icef --help describes them)\n";
    return 1;
  }
  const auto [command, first_argument] = NamedCommand(app, argc, argv);
  if (const std::string option = UnknownOption(command, first_argument, argc, argv); !option.empty()) {
    std::string name = command->get_name();  // "icef train", "icef bench merge"
    for (CLI::App* parent = command->get_parent(); parent != nullptr; parent = parent->get_parent())
      name = parent->get_name() + " " + name;
    std::cerr << name << ": unknown option '" << option << "' (" << name << " --help lists the options)\n";
    return 1;
  }
  return std::nullopt;
}

// Runs the parsed subcommand: 0, 1 with its error on stderr, or 2 for an internal error.
int RunParsed(const std::map<CLI::App*, icef::cli::CommandFn>& runners) {
  try {
    for (const auto& [sub, run] : runners) {
      if (!sub->parsed()) continue;
      const icef::Status status = run();
      if (!status.ok()) {
        std::cerr << "icef " << sub->get_name() << ": error: " << status.message() << "\n";
        return 1;
      }
    }
    return 0;
  } catch (const icef::InternalError& e) {
    std::cerr << "icef: internal error (please report): " << e.what() << "\n";
  } catch (const std::bad_alloc&) {
    std::cerr << "icef: out of memory\n";
  } catch (const std::exception& e) {
    std::cerr << "icef: internal error (please report): " << e.what() << "\n";
  }
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "ICEF: Identity-Consistent Expression Fields. Few-shot, expression-controllable neural head "
      "models from K = 3-10 posed photos.",
      "icef"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "icef 0.1.0");
  std::map<CLI::App*, icef::cli::CommandFn> runners;
  for (const Command& command : kCommands) {
    CLI::App* sub = app.add_subcommand(command.name, command.description);
    runners[sub] = command.add(*sub);
  }
  if (const std::optional<int> rejected = RejectCommandLine(app, argc, argv)) return *rejected;
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 1;
  }
  return RunParsed(runners);
}
