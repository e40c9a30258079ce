icef_module(train DEPS icef_model TEST_DEPS icef_testing icef_synth)
if(TARGET icef_train_test)
  # config_defaults_test compares docs/config.md with the generated key table.
  target_compile_definitions(icef_train_test PRIVATE ICEF_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()
