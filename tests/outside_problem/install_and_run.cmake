# ctest driver of the outside-project example (not part of the example itself):
#   cmake -DBACKBONE_BINARY_DIR=<build> [-DCMAKE_CXX_COMPILER=...] [-DCMAKE_CXX_COMPILER_LAUNCHER=...]
#         [-DCONSUMER_CXX_FLAGS=...]   (the backbone build's CMAKE_CXX_FLAGS, e.g. sanitizers)
#         -P tests/outside_problem/install_and_run.cmake
# 1. installs the build into <build>/outside_problem/prefix (cmake --install),
# 2. configures this folder in a fresh <build>/outside_problem/build with CMAKE_PREFIX_PATH set
#    to that prefix (searched first by find_package), so the example sees the installed package,
# 3. builds it and runs outside_pendulum, which exits non-zero when a period is off by > 1e-9.
# Any failing step fails the test with the step's output.
cmake_minimum_required(VERSION 3.25)
if(NOT BACKBONE_BINARY_DIR)
  message(FATAL_ERROR "BACKBONE_BINARY_DIR: must be the backbone build directory")
endif()
set(work ${BACKBONE_BINARY_DIR}/outside_problem)
set(prefix ${work}/prefix)
set(build ${work}/build)
file(REMOVE_RECURSE ${work})

function(run_step name)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${name} failed (${status}):\n${out}")
  endif()
  message(STATUS "${name}: ok")
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

run_step("install" ${CMAKE_COMMAND} --install ${BACKBONE_BINARY_DIR} --prefix ${prefix})
set(configure_args -S ${CMAKE_CURRENT_LIST_DIR} -B ${build} -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${prefix})
if(CMAKE_CXX_COMPILER)
  list(APPEND configure_args -DCMAKE_CXX_COMPILER=${CMAKE_CXX_COMPILER})
endif()
if(CMAKE_CXX_COMPILER_LAUNCHER)
  list(APPEND configure_args -DCMAKE_CXX_COMPILER_LAUNCHER=${CMAKE_CXX_COMPILER_LAUNCHER})
endif()
if(CONSUMER_CXX_FLAGS)
  list(APPEND configure_args "-DCMAKE_CXX_FLAGS=${CONSUMER_CXX_FLAGS}")
endif()
run_step("configure" ${CMAKE_COMMAND} ${configure_args})
run_step("build" ${CMAKE_COMMAND} --build ${build} -j 2)
run_step("run" ${build}/outside_pendulum)
message("${step_output}")
