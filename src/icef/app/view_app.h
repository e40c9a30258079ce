// `icef view`: an avatar in the browser. Writes a self-contained folder: index.html (the viewer,
// web/viewer/index.html, built into the tool), avatar.glb (icef export's, or the GLB given),
// viewer.json (title, background, the dataset cameras of the model's training frames as train:K,
// the curves file if any) and the parts of three.js it uses (npm package `three`, installed by
// scripts/install-deps.sh in kThreeDir), so the folder can be copied anywhere and served by any web
// server. The page: orbit, a slider per morph target, presets, a dataset camera exactly, and
// playback of ARKit curves in Live Link Face's CSV layout. `--serve` serves the folder on
// 127.0.0.1 (browsers do not load ES modules from file://).
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <ostream>
#include <string>

#include "icef/app/export_app.h"
#include "icef/core/status.h"

namespace icef {

// Where scripts/install-deps.sh puts the npm package `three` (ICEF_THREE_DIR overrides).
inline constexpr const char* kThreeDir = "/usr/local/share/icef/three";

struct ViewAppOptions {
  std::filesystem::path input;  // a model directory or checkpoint, a .glb, or (with serve) a viewer folder
  std::filesystem::path out;    // the folder to write (must not exist, or be empty)
  std::optional<std::filesystem::path> curves;  // an ARKit CSV the page loads and plays
  ExportAppOptions export_options;              // for a model: how it is exported (model and out unused)
  bool serve = false;                           // serve the folder on 127.0.0.1 afterwards
  int port = 8000;                              // with serve: the port (0 = any free port)
};

// Writes the folder (built beside it and renamed into place), or with an existing viewer folder as
// `input` and `serve`, only serves it. Errors name the file: a missing three.js, a GLB that is not
// one, a CSV that face::ReadArkitCurves refuses, a folder that is not empty.
Status RunView(const ViewAppOptions& options, std::ostream& out);

// Serves `dir` on 127.0.0.1:port (0: any free port) until the process is stopped; `on_listen` gets
// the URL once the port is bound (the CLI prints it).
Status ServeFolder(const std::filesystem::path& dir, int port,
                   const std::function<void(const std::string& url)>& on_listen);

}  // namespace icef
