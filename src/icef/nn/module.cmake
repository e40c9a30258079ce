icef_module(nn DEPS icef_io)
