icef_module(face DEPS icef_math)
