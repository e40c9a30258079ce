# The command-line tool: main + one file per subcommand, each a thin adapter that parses options and
# calls one app function; it links the app module only (whose own dependencies carry the rest), and
# its files include only icef/app/ and icef/core/ headers (scripts/check_layering.sh checks both).
file(GLOB icef_cli_sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/*.cc)
add_executable(icef ${icef_cli_sources})
target_link_libraries(icef PRIVATE icef_app)
set_target_properties(icef PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR})
