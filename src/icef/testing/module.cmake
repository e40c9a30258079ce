icef_module(testing DEPS icef_data)
