# Network inference: forward-only CNN layers, the TF.js weights reader and a TF.js graph-model
# runner, for pretrained networks (eval/'s face-identity ResNet and LPIPS, track/'s face mesh).
# Needs only core and io.
icef_module(infer DEPS icef_io)
if(TARGET icef_infer_test)
  target_compile_definitions(icef_infer_test PRIVATE ICEF_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()
