# Scoring one model: metrics, the face-identity network, LPIPS, the evaluation of a model on a
# dataset's test frames (synthetic tiers) or on real held-out frames. Knows nothing of training: the
# benches that train and compare many models are study/. Its tests build tiny models with train/.
find_package(dlib REQUIRED)
icef_module(eval DEPS icef_model icef_synth icef_landmarks icef_infer dlib::dlib TEST_DEPS icef_train icef_study)
if(TARGET icef_eval_test)
  target_compile_definitions(icef_eval_test PRIVATE ICEF_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()
