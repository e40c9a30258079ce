icef_module(render DEPS icef_math)
