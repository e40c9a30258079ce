icef_module(data DEPS icef_io)
