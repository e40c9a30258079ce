find_package(dlib REQUIRED)
icef_module(landmarks DEPS icef_data icef_infer dlib::dlib TEST_DEPS icef_synth icef_testing)
