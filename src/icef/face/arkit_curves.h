// ARKit blendshape curves in Live Link Face's CSV layout, read into ICT-FaceKit's expression space:
// the avatar driven by what a phone recorded. The first row names the columns: Timecode,
// BlendShapeCount, then the blendshapes (EyeBlinkLeft, JawOpen, ...; any case, ARKit's or ICT's
// spelling: IctModel::ExpressionTargets), and possibly columns with no ICT blendshape (TongueOut,
// HeadYaw, LeftEyePitch, ...), which are ignored and listed. Every other row is one frame.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/face/ict_model.h"

namespace icef::face {

struct ArkitCurves {
  std::vector<std::string> timecodes;        // per frame, as written ("" without a Timecode column)
  std::vector<std::vector<float>> weights;   // per frame [num_expressions], the model's order
  std::vector<std::string> ignored_columns;  // header names with no ICT blendshape
  std::vector<std::string> missing_columns;  // ARKit names the model covers with no column (held at 0)
  std::string ToString() const;
};

// Errors (one line naming the file, and the line and column where it applies): unreadable, no
// header, no blendshape column, a name given twice, a row of another width, a cell that is not a
// finite number, no frames.
Result<ArkitCurves> ReadArkitCurves(const IctModel& model, const std::filesystem::path& csv);

}  // namespace icef::face
