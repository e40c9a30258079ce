// Conversion of our float images to dlib's 8-bit RGB matrices (the face detector, the shape
// predictor and the face-chip extraction all take these).
#pragma once

#include <dlib/matrix.h>
#include <dlib/pixel.h>

#include "icef/io/image.h"

namespace icef {

// Values clamped to [0, 1] and rounded to 8 bits; grey images repeat their channel, alpha is ignored.
dlib::matrix<dlib::rgb_pixel> ToDlibRgb(const Image& image);

}  // namespace icef
