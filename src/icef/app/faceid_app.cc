#include "icef/app/faceid_app.h"

#include <iomanip>
#include <map>
#include <optional>

#include "icef/data/dataset.h"
#include "icef/eval/face_identity.h"
#include "icef/io/image.h"
#include "icef/io/json_util.h"

namespace icef {
namespace {

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

}  // namespace

Status FaceIdAppOptions::Validate() const {
  if (images.empty()) return Status::Error("no images given");
  return Status::Ok();
}

std::string DefaultFaceIdModelDir() { return eval::kDefaultFaceIdModelDir; }

Status RunFaceId(const FaceIdAppOptions& o, std::ostream& out) {
  ICEF_RETURN_IF_ERROR(o.Validate());
  std::map<std::string, std::vector<Vec2f>> known;
  if (!o.landmarks_from.empty()) {
    ICEF_ASSIGN_OR_RETURN(known, DatasetLandmarks(o.landmarks_from.string()));
  }
  eval::FaceIdentityOptions options;
  options.model_dir = o.model_dir.string();
  ICEF_ASSIGN_OR_RETURN(eval::FaceIdentity identity, eval::FaceIdentity::Load(options));

  std::vector<eval::FaceIdentityResult> results;
  Json images = Json::array();
  for (const std::string& path : o.images) {
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

  if (o.json) {
    Json doc = {{"model", eval::ResolveFaceIdModelDir(o.model_dir.string()).string()},
                {"threshold", eval::kSamePersonThreshold},
                {"images", std::move(images)},
                {"pairs", std::move(pairs)}};
    out << FormatJson(doc);
    return Status::Ok();
  }
  for (size_t i = 0; i < images.size(); ++i) {
    out << "image " << i << ": " << o.images[i]
        << " (landmarks: " << images[i]["landmarks"].get<std::string>()
        << ")\n  descriptor: " << images[i]["descriptor"].dump() << "\n";
  }
  if (!pairs.empty()) out << "pairs (same person when distance < " << eval::kSamePersonThreshold << "):\n";
  for (const Json& pair : pairs) {
    out << "  " << pair["a"].get<int>() << " - " << pair["b"].get<int>() << "  distance " << std::fixed
        << std::setprecision(4) << pair["distance"].get<double>() << "  cosine "
        << pair["cosine"].get<double>() << "  "
        << (pair["same_person"].get<bool>() ? "same person" : "different people") << "\n"
        << std::defaultfloat;
  }
  return Status::Ok();
}

}  // namespace icef
