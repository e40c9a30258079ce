find_package(Ceres REQUIRED)  # the face-model fit (face_fit.cc)
icef_module(face DEPS icef_math Ceres::ceres)
