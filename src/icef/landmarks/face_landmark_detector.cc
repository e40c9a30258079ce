#include "icef/landmarks/face_landmark_detector.h"

#include <dlib/image_processing.h>
#include <dlib/image_processing/frontal_face_detector.h>
#include <dlib/image_transforms.h>
#include <dlib/serialize.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "icef/landmarks/dlib_image.h"

namespace icef {
namespace {

// dlib coordinates (pixel centres at integers) of the image that was searched -> ours.
Vec2f FromDlib(dlib::dpoint p, bool upsampled) {
  if (upsampled) p = dlib::pyramid_down<2>().point_down(p);  // undoes dlib::pyramid_up
  return Vec2f(float(p.x() + 0.5), float(p.y() + 0.5));
}

std::array<int, 68> MakeMirrorIndex() {
  std::array<int, 68> m{};
  for (int i = 0; i < 68; ++i) m[i] = i;
  auto pair = [&m](int a, int b) { m[a] = b, m[b] = a; };
  for (int i = 0; i <= 7; ++i) pair(i, 16 - i);     // jaw line
  for (int i = 17; i <= 21; ++i) pair(i, 43 - i);   // brows 17-21 <-> 26-22
  for (int i = 31; i <= 32; ++i) pair(i, 66 - i);   // nostrils 31, 32 <-> 35, 34
  for (int i = 36; i <= 39; ++i) pair(i, 81 - i);   // upper eye lids 36-39 <-> 45-42
  pair(40, 47), pair(41, 46);                       // lower eye lids
  for (int i = 48; i <= 50; ++i) pair(i, 102 - i);  // upper outer lip 48-50 <-> 54-52
  pair(55, 59), pair(56, 58);                       // lower outer lip
  pair(60, 64), pair(61, 63), pair(65, 67);         // inner lips
  return m;
}

}  // namespace

const std::array<int, 68>& FaceLandmarkDetector::MirrorIndex() {
  static const std::array<int, 68> m = MakeMirrorIndex();
  return m;
}

std::string FaceDetection::ToString() const {
  std::ostringstream s;
  s << "FaceDetection(landmarks=" << landmarks.size() << ", box=[" << box_min.x() << ", " << box_min.y()
    << "]-[" << box_max.x() << ", " << box_max.y() << "], faces=" << num_faces
    << ", upsampled=" << (upsampled ? "yes" : "no") << ")";
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

Result<FaceDetection> FaceLandmarkDetector::DetectFace(const Image& image, bool averaged) const {
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
  const auto largest = std::max_element(faces.begin(), faces.end(),
                                        [](const auto& a, const auto& b) { return a.area() < b.area(); });
  out.num_faces = int(faces.size());
  out.landmarks.assign(68, Vec2f::Zero());
  if (!averaged) {
    const dlib::full_object_detection shape = (*impl_->predictor)(img, *largest);
    for (unsigned long i = 0; i < shape.num_parts(); ++i)
      out.landmarks[i] = FromDlib(dlib::dpoint(shape.part(i)), out.upsampled);
  } else {
    // dlib coordinates: x -> (columns - 1) - x mirrors the image about its centre, pixel centres
    // at integers; a box [l, r] becomes [w - 1 - r, w - 1 - l].
    dlib::matrix<dlib::rgb_pixel> mirrored;
    dlib::flip_image_left_right(img, mirrored);
    const double w1 = double(img.nc() - 1);
    const double step = kAveragedShift * double(largest->width());
    std::array<dlib::dpoint, 68> sum{};
    int runs = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const dlib::rectangle box = dlib::translate_rect(
            *largest, dlib::point(long(std::lround(dx * step)), long(std::lround(dy * step))));
        const dlib::full_object_detection a = (*impl_->predictor)(img, box);
        const dlib::rectangle mbox(long(w1) - box.right(), box.top(), long(w1) - box.left(), box.bottom());
        const dlib::full_object_detection b = (*impl_->predictor)(mirrored, mbox);
        for (int i = 0; i < 68; ++i) {
          const dlib::point q = b.part(MirrorIndex()[i]);
          sum[i] += dlib::dpoint(a.part(i)) + dlib::dpoint(w1 - double(q.x()), double(q.y()));
        }
        runs += 2;
      }
    for (int i = 0; i < 68; ++i) out.landmarks[i] = FromDlib(sum[i] / double(runs), out.upsampled);
  }
  // A box's corners are pixel centres in dlib; ours bound the pixels.
  out.box_min = FromDlib(dlib::dpoint(largest->left(), largest->top()), out.upsampled) - Vec2f(0.5f, 0.5f);
  out.box_max =
      FromDlib(dlib::dpoint(largest->right(), largest->bottom()), out.upsampled) + Vec2f(0.5f, 0.5f);
  return out;
}

Result<std::vector<Vec2f>> FaceLandmarkDetector::Detect(const Image& image) const {
  ICEF_ASSIGN_OR_RETURN(FaceDetection face, DetectFace(image));
  return std::move(face.landmarks);
}

}  // namespace icef
