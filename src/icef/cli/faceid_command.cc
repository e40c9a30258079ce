// icef faceid IMAGE... [--landmarks-from DATASET] [--json] [--faceid-model DIR]: app/faceid_app.h.
#include <iostream>
#include <memory>
#include <string>

#include "icef/app/faceid_app.h"
#include "icef/cli/commands.h"

namespace icef::cli {

CommandFn RegisterFaceId(CLI::App& app) {
  auto args = std::make_shared<FaceIdAppOptions>();
  app.add_option("images", args->images, "Photos (PNG / JPEG) with one face each")->required();
  app.add_option("--landmarks-from", args->landmarks_from,
                 "Dataset directory whose frames' 68 landmarks are used for the images it holds "
                 "(others use dlib's face detector)");
  app.add_option("--faceid-model", args->model_dir,
                 "Directory with face_recognition_model{.bin,-weights_manifest.json} (default: "
                 "$ICEF_FACEID_MODEL, else " +
                     DefaultFaceIdModelDir() + ")");
  app.add_flag("--json", args->json, "Print one JSON document (descriptors, pairs)");
  return [args]() { return RunFaceId(*args, std::cout); };
}

}  // namespace icef::cli
