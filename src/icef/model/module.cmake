icef_module(model DEPS icef_field icef_render icef_face TEST_DEPS icef_testing)
