// dlib's landmark convention on the face model. The face model's 68 landmarks are where its own
// design puts them (the synthetic ground truth uses them); dlib's detector, run on renders of the
// same head (DetectFace averaged, as the tracker runs it), puts some elsewhere: its jaw line
// follows the silhouette up to the temples, its brows sit lower, its mouth corners wider. The tracker fits
// the model to dlib's landmarks, so it moves each landmark's canonical point by the offset measured here
// before the expression warp (face::FaceModel::Landmarks with offsets). The offset depends on the view
// (dlib's jaw line is the silhouette, its eye corners and nose drift as the head turns): it is linear in
// ViewFeatures of the direction from the head towards the camera. The table comes from
// `icef track --calibrate-detector` (app/detector_calibration.h: validation identities 101-112,
// 35 views each, neutral).
#pragma once

#include <array>
#include <span>

#include "icef/math/types.h"

namespace icef::track {

// The features the offsets are linear in: [1, v.x, v.y, v.x^2] of the unit direction v from the
// head frame's origin towards the camera centre `camera_head` (head frame).
std::array<float, 4> ViewFeatures(const Vec3f& camera_head);

// Which detector's 68 landmarks: dlib's shape predictor (averaged, FaceLandmarkDetector) or the
// 68 points read off MediaPipe's face mesh (landmarks/face_mesh.h, DetectFaceWithMesh).
enum class LandmarkDetector { kDlib, kMesh };
const char* LandmarkDetectorName(LandmarkDetector detector);  // "dlib", "mesh"

// Canonical offsets (head units) from the face model's landmarks to the detector's, per iBUG-68
// index, for a camera centred at `camera_head` (head frame). The face mesh's table is
// mesh_landmarks.inc, measured the same way (`icef track --calibrate-detector --detector mesh`).
std::array<Vec3f, 68> DetectorLandmarkOffsets(LandmarkDetector detector, const Vec3f& camera_head);
std::array<Vec3f, 68> DlibLandmarkOffsets(const Vec3f& camera_head);  // DetectorLandmarkOffsets(kDlib, ...)

}  // namespace icef::track
