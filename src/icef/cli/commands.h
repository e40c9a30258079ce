// Each subcommand registers its options on the app and returns the function that runs it.
// A command returns a Status: the CLI prints a failed one on stderr and exits 1; an
// InternalError (a bug) exits 2.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

#include "icef/core/status.h"

namespace icef::cli {

using CommandFn = std::function<Status()>;

CommandFn RegisterInfo(CLI::App& app);
CommandFn RegisterImport(CLI::App& app);
CommandFn RegisterMask(CLI::App& app);
CommandFn RegisterFaceId(CLI::App& app);
CommandFn RegisterEval(CLI::App& app);
CommandFn RegisterBench(CLI::App& app);
CommandFn RegisterDemo(CLI::App& app);
CommandFn RegisterTrain(CLI::App& app);
CommandFn RegisterRender(CLI::App& app);
CommandFn RegisterExport(CLI::App& app);
CommandFn RegisterView(CLI::App& app);
CommandFn RegisterConfig(CLI::App& app);
CommandFn RegisterSynth(CLI::App& app);
CommandFn RegisterSheet(CLI::App& app);
CommandFn RegisterLandmarks(CLI::App& app);
CommandFn RegisterTrack(CLI::App& app);

}  // namespace icef::cli
