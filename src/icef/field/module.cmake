icef_module(field DEPS icef_nn icef_data)
