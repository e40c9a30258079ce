icef_module(data DEPS icef_io TEST_DEPS icef_testing)
