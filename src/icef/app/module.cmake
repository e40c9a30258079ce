icef_module(app DEPS icef_train icef_eval icef_study icef_synth icef_track icef_video icef_mesh TEST_DEPS icef_testing)
