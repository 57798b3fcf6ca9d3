# ctest driver of the outside examples (problems/examples/): each is a project of its own that
# finds backbone as an installed package and builds its own CLI with backbone_add_cli.
#   cmake -DBACKBONE_BINARY_DIR=<build> -DEXAMPLES_DIR=<source>/problems/examples
#         [-DCMAKE_CXX_COMPILER=...] [-DCMAKE_CXX_COMPILER_LAUNCHER=...]
#         [-DCONSUMER_CXX_FLAGS=...]   (the backbone build's CMAKE_CXX_FLAGS, e.g. sanitizers)
#         -P tests/problems/examples/install_and_run.cmake
# 1. installs the build into <build>/examples/prefix (cmake --install), checks that the shipped
#    scenes are there and that the installed `backbone` traces one from another folder,
# 2. configures each example in a fresh <build>/examples/<name> with CMAKE_PREFIX_PATH set to
#    that prefix (searched first by find_package), so it sees the installed package only,
# 3. builds it and runs its CLI: `--help`, `trace` on the example's scene (exit 0: the branch
#    reached its bound), `inspect` on the last traced point, and for the pendulum
#    `bench --case period_error` (exit 0: every period within 1e-9 of the exact one); the
#    bilinear oscillator (a forced hybrid problem) writes its multipliers and refuses a forcing
#    frequency <= 0.
# Any failing step fails the test with the step's output.
cmake_minimum_required(VERSION 3.25)
foreach(required BACKBONE_BINARY_DIR EXAMPLES_DIR)
  if(NOT ${required})
    message(FATAL_ERROR "${required} must be set")
  endif()
endforeach()
set(work ${BACKBONE_BINARY_DIR}/examples)
set(prefix ${work}/prefix)
file(REMOVE_RECURSE ${work})

function(run_step name)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${name} failed (${status}):\n${out}")
  endif()
  message(STATUS "${name}: ok")
  string(REGEX REPLACE "\n$" "" out "${out}")
  string(REGEX MATCH "[^\n]*\n?[^\n]*$" tail "${out}")
  message("${tail}")
endfunction()

run_step("install" ${CMAKE_COMMAND} --install ${BACKBONE_BINARY_DIR} --prefix ${prefix})
# The shipped scenes are installed, and the installed CLI traces one from any folder.
foreach(shipped problems/contact_bar/scenes/paper.ini problems/duffing/scenes/duffing.ini
                problems/contact_bar/bench/peers/lu_legrand_runs.csv)
  if(NOT EXISTS ${prefix}/share/backbone/${shipped})
    message(FATAL_ERROR "install: ${shipped} is not installed under share/backbone")
  endif()
endforeach()
file(MAKE_DIRECTORY ${work}/elsewhere)
execute_process(COMMAND ${prefix}/bin/backbone trace problems/duffing/scenes/duffing.ini
                        --bound amplitude:0.005:0.1 --out ${work}/out/installed_duffing
                WORKING_DIRECTORY ${work}/elsewhere RESULT_VARIABLE status
                OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "installed backbone trace of a shipped scene failed (${status}):\n${out}")
endif()
message(STATUS "installed backbone traces a shipped scene: ok")

function(build_example name)
  set(build ${work}/${name})
  set(configure_args -S ${EXAMPLES_DIR}/${name} -B ${build} -DCMAKE_BUILD_TYPE=Release
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
  run_step("${name}: configure" ${CMAKE_COMMAND} ${configure_args})
  run_step("${name}: build" ${CMAKE_COMMAND} --build ${build} -j 2)
endfunction()

build_example(pendulum)
set(cli ${work}/pendulum/pendulum_backbone)
run_step("pendulum: --help" ${cli} --help)
run_step("pendulum: trace" ${cli} trace ${EXAMPLES_DIR}/pendulum/scenes/pendulum.ini
         --out ${work}/out/pendulum)
run_step("pendulum: inspect" ${cli} inspect ${work}/out/pendulum/scene.ini
         --orbit ${work}/out/pendulum/orbits.csv:5)
run_step("pendulum: bench" ${cli} bench --case period_error --out ${work}/out/bench)

build_example(minimal)
set(cli ${work}/minimal/minimal_backbone)
run_step("minimal: trace" ${cli} trace ${EXAMPLES_DIR}/minimal/scenes/fold.ini
         --out ${work}/out/fold)
run_step("minimal: inspect" ${cli} inspect ${work}/out/fold/scene.ini
         --orbit ${work}/out/fold/orbits.csv:5)

# A forced hybrid problem with events, traced with the stability of its orbits.
build_example(bilinear)
set(cli ${work}/bilinear/bilinear_backbone)
run_step("bilinear: trace" ${cli} trace ${EXAMPLES_DIR}/bilinear/scenes/bilinear.ini
         --out ${work}/out/bilinear)
foreach(written branch.csv multipliers.csv bifurcations.csv)
  if(NOT EXISTS ${work}/out/bilinear/${written})
    message(FATAL_ERROR "bilinear: trace wrote no ${written}")
  endif()
endforeach()
# A forcing frequency <= 0 is refused before any work: exit 2, nothing written.
execute_process(COMMAND ${cli} trace ${EXAMPLES_DIR}/bilinear/scenes/bilinear.ini --frequency -1
                        --out ${work}/out/bilinear_bad
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT status EQUAL 2 OR EXISTS ${work}/out/bilinear_bad)
  message(FATAL_ERROR "bilinear: --frequency -1 gave exit ${status} (expected 2, nothing written):\n${out}")
endif()
message(STATUS "bilinear: --frequency -1 refused: ok")
