icef_module(io DEPS icef_math nlohmann_json::nlohmann_json gif PNG::PNG JPEG::JPEG ZLIB::ZLIB)
target_include_directories(icef_io SYSTEM PUBLIC ${STB_INCLUDE_DIR})
if(TARGET icef_io_test)
  # image_test reads the image fuzzer's seed corpus (fuzz/corpus/image) as regression inputs.
  target_compile_definitions(icef_io_test PRIVATE ICEF_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()
