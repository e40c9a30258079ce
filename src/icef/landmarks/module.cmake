find_package(dlib REQUIRED)
icef_module(landmarks DEPS icef_data dlib::dlib TEST_DEPS icef_synth icef_testing)
