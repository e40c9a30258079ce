icef_module(synth DEPS icef_data icef_face)
