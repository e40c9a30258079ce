icef_module(math DEPS icef_core)
