// The tracker's fit on ICT-FaceKit (`icef track --face-model ict`): face::FitIctToLandmarks
// (face/ict_fit.h) on the photos' landmarks, given in the terms the rest of the tracker
// uses (track/track_fit.h's TrackFit: per-photo camera-from-world, expression weights, the
// model's own landmarks in the world frame), and the fitted head's silhouette and bounds that the
// crop and the mask start from.
//
// The dataset's world frame is the ICT head frame (cm) scaled and shifted by one fixed
// similarity, WorldFromIctHead: 1 world unit = 1 / kWorldPerCm cm, origin near the centre of the
// head, so a tracked ICT dataset has the size and placement of the renderer's defaults (its
// aabb, step sizes and the crop's head box are those of a head ~0.9 units tall around the
// origin; the constants are a least-squares fit of the mean ICT face's landmarks 17-67 to those
// places). The axes are ICT's: +y up, the face looks down +z, the subject's left is +x.
#pragma once

#include <span>
#include <vector>

#include "icef/core/status.h"
#include "icef/face/face_fit.h"
#include "icef/face/ict_fit.h"
#include "icef/face/ict_model.h"
#include "icef/io/image.h"
#include "icef/io/json_util.h"
#include "icef/math/camera.h"
#include "icef/math/ray.h"
#include "icef/track/track_fit.h"

namespace icef::track {

constexpr double kWorldPerCm = 0.026;
// x_world = kWorldPerCm * x_ict + WorldFromIctHead().translation.
face::Similarity WorldFromIctHead();

// ICT fitted to the frames' landmarks_2d with their intrinsics (silhouettes and photos are not
// used). Without camera poses, each frame's head pose is its own and the world frame is
// WorldFromIctHead's; when every frame has world_from_cam (a dataset's known cameras), one head
// pose is fitted among them (face::IctObservation::cam_from_world), the world frame is the
// dataset's and head_from_world the fitted similarity. In the result, frames[i].cam_from_head is
// the camera from the world frame (rigid, world units; the known camera as it was), expression the
// 53 weights in the model's order, landmarks_head the fitted model's 68 landmarks in the world
// frame, projected / rms_iod / max_iod / landmarks_used the fit's (all 68 landmarks, no outliers
// dropped); ict_identity the identity coefficients; shape stays the procedural default. Errors:
// those of FitIctToLandmarks.
Result<TrackFit> FitIctTrack(const face::IctModel& model, std::span<const TrackFrame> frames,
                             const face::IctFitOptions& options = {});

// The report fields of an ICT fit (track/report.json): "face_model": "ict" and "ict_identity",
// the fit's identity coefficients.
void AddIctReportFields(const TrackFit& fit, Json* report);

// The parts of the posed head whose outline is the head's: face and head_neck.
std::vector<std::array<uint32_t, 3>> IctOuterTriangles(const face::IctModel& model);

// 1 where the posed head (identity, expression; the triangles of IctOuterTriangles) covers a pixel
// of `camera` (world frame: the dataset's), else 0; 1 channel.
Image IctSilhouette(const face::IctModel& model, std::span<const float> identity,
                    std::span<const float> expression, const Camera& camera);

// The world-frame box of the neutral head of this identity, widened by `margin` (world units).
Aabb IctHeadBounds(const face::IctModel& model, std::span<const float> identity, float margin);

}  // namespace icef::track
