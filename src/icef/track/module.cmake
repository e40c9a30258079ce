# OpenCV (Debian's split libopencv-imgproc-dev ships no CMake config): core + imgproc for the crops
# and GrabCut. libexif for the photos' focal lengths.
find_path(OpenCV_INCLUDE_DIR opencv2/imgproc.hpp PATH_SUFFIXES opencv4 REQUIRED)
find_library(OpenCV_CORE_LIBRARY opencv_core REQUIRED)
find_library(OpenCV_IMGPROC_LIBRARY opencv_imgproc REQUIRED)
find_path(EXIF_INCLUDE_DIR libexif/exif-data.h REQUIRED)
find_library(EXIF_LIBRARY exif REQUIRED)
add_library(icef_opencv INTERFACE)
target_include_directories(icef_opencv SYSTEM INTERFACE ${OpenCV_INCLUDE_DIR} ${EXIF_INCLUDE_DIR})
target_link_libraries(icef_opencv INTERFACE ${OpenCV_IMGPROC_LIBRARY} ${OpenCV_CORE_LIBRARY} ${EXIF_LIBRARY})
icef_module(track DEPS icef_face icef_data icef_infer icef_landmarks icef_opencv TEST_DEPS icef_synth)
