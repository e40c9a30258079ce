#include "icef/landmarks/face_landmark_detector.h"
#include "icef/landmarks/dlib_image.h"

#include <dlib/image_processing.h>
#include <dlib/image_processing/frontal_face_detector.h>
#include <dlib/image_transforms.h>
#include <dlib/serialize.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace icef {
namespace {

// dlib coordinates (pixel centres at integers) of the image that was searched -> ours.
Vec2f FromDlib(dlib::dpoint p, bool upsampled) {
  if (upsampled) p = dlib::pyramid_down<2>().point_down(p);  // undoes dlib::pyramid_up
  return Vec2f(float(p.x() + 0.5), float(p.y() + 0.5));
}

}  // namespace

std::string FaceDetection::ToString() const {
  std::ostringstream s;
  s << "FaceDetection(landmarks=" << landmarks.size() << ", box=[" << box_min.x() << ", " << box_min.y() << "]-["
    << box_max.x() << ", " << box_max.y() << "], faces=" << num_faces << ", upsampled=" << (upsampled ? "yes" : "no")
    << ")";
  return s.str();
}

struct FaceLandmarkDetector::Impl {
  dlib::frontal_face_detector detector = dlib::get_frontal_face_detector();  // keeps scratch state
  std::shared_ptr<const dlib::shape_predictor> predictor;                    // thread-safe (dlib docs)
};

Result<FaceLandmarkDetector> FaceLandmarkDetector::Load(const std::filesystem::path& predictor_path) {
  const std::filesystem::path path = predictor_path.empty() ? kDefaultShapePredictorPath : predictor_path;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    return Status::Error(path.string() +
                         ": 68-point shape predictor not found (Debian package libdlib-data; "
                         "scripts/install-deps.sh installs it)");
  auto predictor = std::make_shared<dlib::shape_predictor>();
  try {
    dlib::deserialize(path.string()) >> *predictor;
  } catch (const std::exception& e) {
    return Status::Error(path.string() + ": cannot read shape predictor: " + e.what());
  }
  if (predictor->num_parts() != 68)
    return Status::Error(path.string() + ": shape predictor has " + std::to_string(predictor->num_parts()) +
                         " parts, expected the 68-point iBUG model");
  FaceLandmarkDetector out;
  out.impl_ = std::make_shared<Impl>();
  out.impl_->predictor = std::move(predictor);
  return out;
}

FaceLandmarkDetector FaceLandmarkDetector::Clone() const {
  ICEF_CHECK(impl_ != nullptr, "Clone() of a detector that was not loaded");
  FaceLandmarkDetector out;
  out.impl_ = std::make_shared<Impl>(*impl_);
  return out;
}

Result<FaceDetection> FaceLandmarkDetector::DetectFace(const Image& image) const {
  ICEF_CHECK(impl_ != nullptr, "DetectFace() on a detector that was not loaded");
  if (image.empty()) return Status::Error("face detector: empty image");
  dlib::matrix<dlib::rgb_pixel> img = ToDlibRgb(image);
  FaceDetection out;
  std::vector<dlib::rectangle> faces = impl_->detector(img);
  if (faces.empty()) {
    dlib::pyramid_up(img);  // with dlib::pyramid_down<2>, whose point_down maps back
    out.upsampled = true;
    faces = impl_->detector(img);
  }
  if (faces.empty()) return Status::Error("no face found");
  // The first of the largest boxes (dlib returns them in a fixed order): deterministic.
  const auto largest = std::max_element(faces.begin(), faces.end(), [](const auto& a, const auto& b) {
    return a.area() < b.area();
  });
  const dlib::full_object_detection shape = (*impl_->predictor)(img, *largest);
  out.num_faces = int(faces.size());
  out.landmarks.resize(shape.num_parts());
  for (unsigned long i = 0; i < shape.num_parts(); ++i) out.landmarks[i] = FromDlib(dlib::dpoint(shape.part(i)), out.upsampled);
  // A box's corners are pixel centres in dlib; ours bound the pixels.
  out.box_min = FromDlib(dlib::dpoint(largest->left(), largest->top()), out.upsampled) - Vec2f(0.5f, 0.5f);
  out.box_max = FromDlib(dlib::dpoint(largest->right(), largest->bottom()), out.upsampled) + Vec2f(0.5f, 0.5f);
  return out;
}

Result<std::vector<Vec2f>> FaceLandmarkDetector::Detect(const Image& image) const {
  ICEF_ASSIGN_OR_RETURN(FaceDetection face, DetectFace(image));
  return std::move(face.landmarks);
}

}  // namespace icef
