# ctest driver (cmake -P): installs imufit from its build tree into a temporary prefix, then
# configures, builds and runs tests/consumer against that prefix alone.
#
# -D IMUFIT_BUILD_DIR   imufit's build tree        -D CONSUMER_SOURCE_DIR  tests/consumer
# -D WORK_DIR           scratch folder (wiped)     -D GENERATOR, MAKE_PROGRAM, CXX_COMPILER, CONFIG
cmake_minimum_required(VERSION 3.20)

function(run_step name)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "consumer test: ${name} failed (${status}):\n${out}")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
set(build "${WORK_DIR}/build")

set(config_args)
if(CONFIG)
  set(config_args --config "${CONFIG}")
endif()
run_step("install" "${CMAKE_COMMAND}" --install "${IMUFIT_BUILD_DIR}" --prefix "${prefix}" ${config_args})

set(configure_args -S "${CONSUMER_SOURCE_DIR}" -B "${build}" -G "${GENERATOR}" "-DCMAKE_PREFIX_PATH=${prefix}"
                   "-DCMAKE_FIND_PACKAGE_NO_PACKAGE_REGISTRY=ON" "-DCMAKE_BUILD_TYPE=Release")
if(MAKE_PROGRAM)
  list(APPEND configure_args "-DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM}")
endif()
if(CXX_COMPILER)
  list(APPEND configure_args "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}")
endif()
run_step("configure" "${CMAKE_COMMAND}" ${configure_args})

# The package must have come from the temporary prefix, not from a build tree or the system.
file(STRINGS "${build}/CMakeCache.txt" found REGEX "^imufit_DIR:")
string(FIND "${found}" "${prefix}/" at)
if(NOT at GREATER_EQUAL 0)
  message(FATAL_ERROR "consumer test: imufit was found elsewhere than ${prefix}: ${found}")
endif()

run_step("build" "${CMAKE_COMMAND}" --build "${build}" ${config_args})
set(program "${build}/consumer")
if(CONFIG AND EXISTS "${build}/${CONFIG}/consumer")
  set(program "${build}/${CONFIG}/consumer")
endif()
run_step("run" "${program}")
message(STATUS "consumer: ${step_output}")
file(REMOVE_RECURSE "${WORK_DIR}")
