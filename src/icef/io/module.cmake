icef_module(io DEPS icef_math nlohmann_json::nlohmann_json gif)
target_include_directories(icef_io SYSTEM PUBLIC ${STB_INCLUDE_DIR})
