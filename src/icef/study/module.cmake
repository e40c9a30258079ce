# The benches: controllers that synthesise or track datasets, train every (identity, K, method) run,
# score it with eval/, and aggregate, judge and report the lot (Markdown, JSON, LaTeX, plots).
icef_module(study DEPS icef_train icef_eval icef_synth TEST_DEPS icef_testing)
if(TARGET icef_study_test)
  target_compile_definitions(icef_study_test PRIVATE ICEF_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()
