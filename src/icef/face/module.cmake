find_package(Ceres REQUIRED)  # the face-model fit (face_fit.cc)
icef_module(face DEPS icef_math Ceres::ceres)
# IctModel::DefaultPath() falls back to the repository's models/ict-facekit/ict_facekit.bin.
target_compile_definitions(icef_face PRIVATE ICEF_SOURCE_DIR="${PROJECT_SOURCE_DIR}")

# The batched signed distance (face_sdf.cc) vectorises only when std::sqrt need not set errno; no
# value changes.
set_source_files_properties(${PROJECT_SOURCE_DIR}/src/icef/face/face_sdf.cc PROPERTIES COMPILE_OPTIONS -fno-math-errno)
