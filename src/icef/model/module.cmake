icef_module(model DEPS icef_field icef_render icef_face Ceres::ceres TEST_DEPS icef_testing icef_synth)
