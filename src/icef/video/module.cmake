# FFmpeg's libraries as Debian ships them (libavformat/libavcodec/libswscale/libavutil, via
# pkg-config): video decoding for `icef track` and H.264 / MPEG-4 encoding for `icef render --video`.
find_package(PkgConfig REQUIRED)
pkg_check_modules(LIBAV REQUIRED IMPORTED_TARGET libavformat libavcodec libswscale libavutil)
icef_module(video DEPS icef_core icef_io PkgConfig::LIBAV)
