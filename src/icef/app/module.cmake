icef_module(app DEPS icef_train icef_eval icef_synth icef_track TEST_DEPS icef_testing)
