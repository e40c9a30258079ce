// `icef track DRIVING.mp4 --curves out.csv`: a video's expressions and head rotation as ARKit curves
// in Live Link Face's CSV layout, to drive an avatar with someone else's performance
// (`icef render MODEL --expressions out.csv`). Every kept frame is decoded, its 68 landmarks
// detected and dropped (the frames are never all held), then ICT-FaceKit is fitted to all frames at
// once: one identity, the driving person's, which stays in the fit and out of the curves; per frame
// a head pose and the 53 expression weights. A frame without exactly one face gets the curves of the
// nearest frame that has one, so the rows keep the video's timing.
#pragma once

#include <filesystem>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "icef/app/track_app.h"
#include "icef/core/status.h"
#include "icef/face/ict_model.h"

namespace icef {

// One row of the curves: a frame's time, its 53 weights (the model's order) and head rotation.
struct CurveFrame {
  double time_s = 0;
  std::vector<float> weights;           // [53] in [0, 1]
  double yaw = 0, pitch = 0, roll = 0;  // radians (track::TrackedFrame::YawPitchRollDeg's convention)
  bool tracked = true;                  // false: copied from the nearest tracked frame
};

// The CSV: Timecode (HH:MM:SS:FF.mmm at `fps`), BlendShapeCount, one column per ARKit name the model
// covers (EyeBlinkLeft, ..., Live Link Face's capitalisation; a split pair such as browInnerUp_L/_R
// as one column, their mean), then HeadYaw, HeadPitch, HeadRoll in radians. face::ReadArkitCurves
// reads it back.
std::string ArkitCurvesCsv(const face::IctModel& model, std::span<const CurveFrame> frames, double fps);

// Decodes options.photos[0] (one video; --every thins it, --max-frames stops early), tracks it and
// writes `csv` (atomically). Errors: not one video, a video that cannot be read, no frame with a
// face, a fit that fails; nothing is written then.
Status RunTrackCurves(const TrackAppOptions& options, const std::filesystem::path& csv, std::ostream& out);

}  // namespace icef
