icef_module(track DEPS icef_face icef_data)
