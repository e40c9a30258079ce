#include <iostream>
#include <memory>

#include "icef/app/view_app.h"
#include "icef/cli/commands.h"
#include "icef/cli/validators.h"
#include "icef/core/progress.h"

namespace icef::cli {

CommandFn RegisterView(CLI::App& app) {
  app.description(
      "The avatar in a web browser: writes a folder with index.html, the avatar as a GLB (icef export's, "
      "or the .glb given), viewer.json and three.js, which any web server can serve and any browser with "
      "WebGL shows: orbit the head, a slider per expression (ARKit names for models on ICT-FaceKit), "
      "presets, the training cameras exactly, and playback of ARKit curves (Live Link Face's CSV layout, "
      "or icef track VIDEO --curves). --serve serves it on 127.0.0.1 and prints the URL; icef view DIR "
      "--serve serves a folder written before.");
  auto o = std::make_shared<ViewAppOptions>();
  app.add_option("input", o->input,
                 "Model directory or checkpoint, a .glb, or (with --serve) a viewer folder")
      ->required();
  app.add_option("--out", o->out, "The folder to write (must not exist, or be empty)");
  auto curves = std::make_shared<std::string>();
  app.add_option("--curves", *curves, "ARKit curves (CSV, Live Link Face's layout) the page loads and plays");
  app.add_flag("--serve", o->serve, "Serve the folder on 127.0.0.1 and print the URL (Ctrl-C stops)");
  app.add_option("--port", o->port, "With --serve: the port (0 = any free port)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  app.add_option("--resolution", o->export_options.resolution,
                 "For a model: density grid points along the head box's longest side (icef export)")
      ->capture_default_str();
  app.add_option("--triangles", o->export_options.max_triangles, "For a model: triangle budget (icef export)")
      ->capture_default_str();
  auto density = std::make_shared<double>(0);
  app.add_option("--density", *density, "For a model: the surface's density (icef export --density)")
      ->check(CLI::PositiveNumber);
  app.add_option("--threads", o->export_options.threads, "Worker threads (0 = all cores)")
      ->check(kNonNegative);
  return [=]() -> Status {
    ViewAppOptions opts = *o;
    if (!curves->empty()) opts.curves = *curves;
    if (*density > 0) opts.export_options.density = *density;
    opts.export_options.progress = StdoutIsTerminal();
    return RunView(opts, std::cout);
  };
}

}  // namespace icef::cli
