icef_module(app DEPS icef_train icef_synth icef_track)
