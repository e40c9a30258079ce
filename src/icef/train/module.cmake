icef_module(train DEPS icef_model TEST_DEPS icef_testing icef_synth)
