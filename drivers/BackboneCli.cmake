# backbone_add_cli(<executable> PLUGINS <name>... [LIBRARIES <target>...] [SOURCES <file>...])
#
# Builds a backbone-style CLI: `<executable> trace|inspect|simulate|bench|figures|reproduce|
# version`, with one plugin per name in PLUGINS. Each name is a namespace whose sources define
#     void backbone::<name>::register_plugin(backbone::cli::PluginRegistry&);
# (continuation/cli/plugin.hpp), compiled from SOURCES or linked from LIBRARIES. The main() is
# generated from main.cpp.in; a plugin named here whose function is missing is a link error.
# Available in this tree (drivers/CMakeLists.txt) and, after find_package(backbone), outside it:
#     find_package(backbone REQUIRED)
#     backbone_add_cli(pendulum_backbone PLUGINS pendulum SOURCES pendulum.cpp)
set(BACKBONE_CLI_TEMPLATE ${CMAKE_CURRENT_LIST_DIR}/main.cpp.in)
function(backbone_add_cli executable)
  cmake_parse_arguments(CLI "" "" "PLUGINS;LIBRARIES;SOURCES" ${ARGN})
  if(NOT CLI_PLUGINS)
    message(FATAL_ERROR "backbone_add_cli(${executable}): name at least one plugin in PLUGINS")
  endif()
  set(declarations "")
  set(calls "")
  foreach(plugin ${CLI_PLUGINS})
    string(APPEND declarations
           "namespace backbone::${plugin} { void register_plugin(cli::PluginRegistry&); }\n")
    string(APPEND calls "  backbone::${plugin}::register_plugin(registry);\n")
  endforeach()
  string(REPLACE ";" ", " plugins "${CLI_PLUGINS}")
  set(main_source ${CMAKE_CURRENT_BINARY_DIR}/${executable}_main.cpp)
  configure_file(${BACKBONE_CLI_TEMPLATE} ${main_source} @ONLY)
  add_executable(${executable} ${main_source} ${CLI_SOURCES})
  target_link_libraries(${executable} PRIVATE backbone::drivers ${CLI_LIBRARIES})
endfunction()
