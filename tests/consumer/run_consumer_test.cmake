# The test Install.ConsumerBuildsAgainstTheInstalledTree (cmake -P, CMakeLists.txt passes the -D's):
# installs the build into <build>/consumer-prefix, configures, builds and runs tests/consumer against
# it in <build>/consumer-build, then checks the pkg-config file. Nothing goes outside the build.
foreach(v WB_BUILD_DIR WB_SOURCE_DIR WB_LIBDIR WB_INCLUDEDIR WB_GENERATOR)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "install test: ${v} not given (run through ctest)")
  endif()
endforeach()
set(prefix "${WB_BUILD_DIR}/consumer-prefix")
set(cbuild "${WB_BUILD_DIR}/consumer-build")
file(REMOVE_RECURSE "${prefix}" "${cbuild}")
set(config_args "")
if(WB_CONFIG)
  set(config_args --config "${WB_CONFIG}")
endif()

# Runs the command after `step`, stopping the test with the step's name when it fails.
function(wb_step step)
  message(STATUS "install test: ${step}")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    list(JOIN ARGN " " command)
    message(FATAL_ERROR "install test FAILED at: ${step} (exit ${rc})\n  command: ${command}")
  endif()
endfunction()

wb_step("cmake --install into ${prefix} (a missing file: the build is not complete, build it first)"
  "${CMAKE_COMMAND}" --install "${WB_BUILD_DIR}" --prefix "${prefix}" ${config_args})
set(cxx_arg "")
if(WB_CXX_COMPILER)
  set(cxx_arg "-DCMAKE_CXX_COMPILER=${WB_CXX_COMPILER}")
endif()
wb_step("configure tests/consumer with find_package(wetbrush) from ${prefix}"
  "${CMAKE_COMMAND}" -S "${WB_SOURCE_DIR}/tests/consumer" -B "${cbuild}" -G "${WB_GENERATOR}"
  "-DCMAKE_PREFIX_PATH=${prefix}" "-DCMAKE_BUILD_TYPE=${WB_CONFIG}" ${cxx_arg}
  -DCMAKE_FIND_PACKAGE_NO_PACKAGE_REGISTRY=ON)
# The package must be the one just installed, not one elsewhere on the machine.
file(STRINGS "${cbuild}/CMakeCache.txt" found_dir REGEX "^wetbrush_DIR:")
string(REGEX REPLACE "^[^=]*=" "" found_dir "${found_dir}")
file(REAL_PATH "${prefix}" real_prefix)
file(REAL_PATH "${found_dir}" found_dir)
string(FIND "${found_dir}" "${real_prefix}/" at)
if(NOT at EQUAL 0)
  message(FATAL_ERROR "install test FAILED: the consumer found wetbrush at ${found_dir}, not in ${prefix}")
endif()
wb_step("build the consumer" "${CMAKE_COMMAND}" --build "${cbuild}" ${config_args})
set(exe "${cbuild}/consumer")
if(NOT EXISTS "${exe}" AND EXISTS "${cbuild}/${WB_CONFIG}/consumer")
  set(exe "${cbuild}/${WB_CONFIG}/consumer")  # a multi-config generator
endif()
wb_step("run the consumer (a short stroke; its paint census must be positive and finite)" "${exe}")

# pkg-config: the installed wetbrush.pc resolves (its Requires.private too) and names the headers.
find_program(WB_PKG_CONFIG NAMES pkg-config pkgconf)
if(NOT WB_PKG_CONFIG)
  message(FATAL_ERROR "install test FAILED: pkg-config not found (Debian package pkg-config)")
endif()
set(ENV{PKG_CONFIG_PATH} "${prefix}/${WB_LIBDIR}/pkgconfig")
foreach(static "" "--static")
  execute_process(COMMAND "${WB_PKG_CONFIG}" --cflags --libs ${static} wetbrush RESULT_VARIABLE rc
    OUTPUT_VARIABLE flags ERROR_VARIABLE err OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "install test FAILED: pkg-config --cflags --libs ${static} wetbrush "
      "(PKG_CONFIG_PATH=$ENV{PKG_CONFIG_PATH}): ${err}")
  endif()
  message(STATUS "install test: pkg-config --cflags --libs ${static} wetbrush: ${flags}")
endforeach()
separate_arguments(flags UNIX_COMMAND "${flags}")
file(REAL_PATH "${prefix}/${WB_INCLUDEDIR}/wetbrush" want_include)
set(include_ok FALSE)
set(lib_ok FALSE)
foreach(f IN LISTS flags)
  if(f MATCHES "^-I(.+)$")
    file(REAL_PATH "${CMAKE_MATCH_1}" dir)
    if(dir STREQUAL want_include AND EXISTS "${dir}/core/sim/simulator.h")
      set(include_ok TRUE)
    endif()
  elseif(f STREQUAL "-lwetbrush")
    set(lib_ok TRUE)
  endif()
endforeach()
if(NOT include_ok OR NOT lib_ok)
  message(FATAL_ERROR "install test FAILED: pkg-config's flags do not name the installed headers "
    "(${want_include}) and -lwetbrush: ${flags}")
endif()
# The installed Python module imports from its installed folder and paints a stroke there.
if(WB_PYTHON_EXE AND WB_PYTHON_DIR)
  set(ENV{PYTHONPATH} "${prefix}/${WB_PYTHON_DIR}")
  wb_step("import the installed Python module and paint with it" "${WB_PYTHON_EXE}"
    "${WB_SOURCE_DIR}/tests/consumer/paint.py" "${prefix}")
endif()
message(STATUS "install test: passed")
