find_package(dlib REQUIRED)
icef_module(eval DEPS icef_data dlib::dlib)
