// icef faceid IMAGE... [--landmarks-from DATASET] [--json] [--faceid-model DIR]
// Each image's 128-D face descriptor (dlib's ResNet, run by eval/face_descriptor) and the
// pairwise Euclidean distances and cosine similarities; pairs under 0.6 are flagged as the same
// person. Landmarks come from the dataset when --landmarks-from names one holding the image,
// otherwise from dlib's face detector.
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "icef/cli/commands.h"
#include "icef/data/dataset.h"
#include "icef/eval/face_identity.h"
#include "icef/io/json_util.h"

namespace icef::cli {
namespace {

struct FaceIdArgs {
  std::vector<std::string> images;
  std::string landmarks_from;
  std::string model_dir;
  bool json = false;
};

std::string CanonicalKey(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(path, ec);
  return ec ? path.lexically_normal().string() : canonical.string();
}

// Image path -> landmarks of every frame (train, test, val) that has them.
Result<std::map<std::string, std::vector<Vec2f>>> DatasetLandmarks(const std::string& dir) {
  ICEF_ASSIGN_OR_RETURN(const Dataset dataset, LoadDataset(dir));
  std::map<std::string, std::vector<Vec2f>> out;
  for (const auto* frames : {&dataset.train, &dataset.test, &dataset.val})
    for (const Frame& frame : *frames)
      if (frame.landmarks_2d.has_value()) out[CanonicalKey(dataset.ImagePath(frame))] = *frame.landmarks_2d;
  return out;
}

Status RunFaceId(const FaceIdArgs& args) {
  std::map<std::string, std::vector<Vec2f>> known;
  if (!args.landmarks_from.empty()) {
    ICEF_ASSIGN_OR_RETURN(known, DatasetLandmarks(args.landmarks_from));
  }
  eval::FaceIdentityOptions options;
  options.model_dir = args.model_dir;
  ICEF_ASSIGN_OR_RETURN(eval::FaceIdentity identity, eval::FaceIdentity::Load(options));

  std::vector<eval::FaceIdentityResult> results;
  Json images = Json::array();
  for (const std::string& path : args.images) {
    ICEF_ASSIGN_OR_RETURN(const Image image, ReadImage(path));
    std::optional<std::vector<Vec2f>> landmarks;
    if (const auto it = known.find(CanonicalKey(path)); it != known.end()) landmarks = it->second;
    Result<eval::FaceIdentityResult> result = identity.Describe(image, landmarks);
    if (!result.ok()) return result.status().WithContext(path);
    Json descriptor = Json::array();
    for (float v : result->descriptor) descriptor.push_back(JsonFloat(v));
    images.push_back({{"path", path},
                      {"landmarks", result->detected ? "detector" : "dataset"},
                      {"descriptor", std::move(descriptor)}});
    results.push_back(std::move(result).value());
  }

  Json pairs = Json::array();
  for (size_t i = 0; i < results.size(); ++i) {
    for (size_t j = i + 1; j < results.size(); ++j) {
      const double distance = eval::DescriptorDistance(results[i].descriptor, results[j].descriptor);
      const double cosine = eval::DescriptorCosine(results[i].descriptor, results[j].descriptor);
      pairs.push_back({{"a", i},
                       {"b", j},
                       {"distance", distance},
                       {"cosine", cosine},
                       {"same_person", distance < eval::kSamePersonThreshold}});
    }
  }

  if (args.json) {
    Json out = {{"model", eval::ResolveFaceIdModelDir(args.model_dir).string()},
                {"threshold", eval::kSamePersonThreshold},
                {"images", std::move(images)},
                {"pairs", std::move(pairs)}};
    std::cout << FormatJson(out);
    return Status::Ok();
  }
  for (size_t i = 0; i < images.size(); ++i) {
    std::cout << "image " << i << ": " << args.images[i] << " (landmarks: " << images[i]["landmarks"].get<std::string>()
              << ")\n  descriptor: " << images[i]["descriptor"].dump() << "\n";
  }
  if (!pairs.empty()) std::cout << "pairs (same person when distance < " << eval::kSamePersonThreshold << "):\n";
  for (const Json& pair : pairs) {
    std::cout << "  " << pair["a"].get<int>() << " - " << pair["b"].get<int>() << "  distance " << std::fixed
              << std::setprecision(4) << pair["distance"].get<double>() << "  cosine " << pair["cosine"].get<double>()
              << "  " << (pair["same_person"].get<bool>() ? "same person" : "different people") << "\n"
              << std::defaultfloat;
  }
  return Status::Ok();
}

}  // namespace

CommandFn RegisterFaceId(CLI::App& app) {
  auto args = std::make_shared<FaceIdArgs>();
  app.add_option("images", args->images, "Photos (PNG / JPEG) with one face each")->required();
  app.add_option("--landmarks-from", args->landmarks_from,
                 "Dataset directory whose frames' 68 landmarks are used for the images it holds "
                 "(others use dlib's face detector)");
  app.add_option("--faceid-model", args->model_dir,
                 "Directory with face_recognition_model{.bin,-weights_manifest.json} (default: "
                 "$ICEF_FACEID_MODEL, else " + std::string(eval::kDefaultFaceIdModelDir) + ")");
  app.add_flag("--json", args->json, "Print one JSON document (descriptors, pairs)");
  return [args]() { return RunFaceId(*args); };
}

}  // namespace icef::cli
