# icef view serves its folder with cpp-httplib (Debian's libcpp-httplib-dev).
find_package(PkgConfig REQUIRED)
pkg_check_modules(HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)
icef_module(app DEPS icef_train icef_eval icef_study icef_synth icef_track icef_video icef_mesh PkgConfig::HTTPLIB
            TEST_DEPS icef_testing)

# The viewer page (web/viewer/index.html) built into the tool as a string literal, regenerated when
# the page changes (app/view_app.cc includes it).
set(icef_viewer_html ${PROJECT_SOURCE_DIR}/web/viewer/index.html)
set(icef_viewer_inc ${CMAKE_BINARY_DIR}/generated/icef/app/viewer_html.inc)
add_custom_command(
  OUTPUT ${icef_viewer_inc}
  COMMAND ${CMAKE_COMMAND} -DIN=${icef_viewer_html} -DOUT=${icef_viewer_inc} -P ${CMAKE_CURRENT_LIST_DIR}/embed_text.cmake
  DEPENDS ${icef_viewer_html} ${CMAKE_CURRENT_LIST_DIR}/embed_text.cmake
  COMMENT "Embedding web/viewer/index.html")
target_sources(icef_app PRIVATE ${icef_viewer_inc})
target_include_directories(icef_app PRIVATE ${CMAKE_BINARY_DIR}/generated)
