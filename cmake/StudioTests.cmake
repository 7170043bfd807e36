# Included by CTest (TEST_INCLUDE_FILES): one test per Qt test function of the studio's test
# binary, each in its own Xvfb server, labelled "studio". The binary lists its functions itself
# (Qt Test's -functions, on the offscreen platform: listing needs no display), so a new test
# function is a new CTest test without editing CMake.
execute_process(COMMAND /usr/bin/env QT_QPA_PLATFORM=offscreen "${WB_STUDIO_TEST_EXE}" -functions
  OUTPUT_VARIABLE _wb_out ERROR_VARIABLE _wb_err RESULT_VARIABLE _wb_rc TIMEOUT 60)
string(REGEX MATCHALL "[A-Za-z_][A-Za-z_0-9]*\\(\\)" _wb_functions "${_wb_out}")
if(NOT _wb_rc EQUAL 0 OR NOT _wb_functions)
  # A test that fails and says why, rather than a studio group that silently has no tests.
  add_test(studio.list_functions /bin/sh -c
    "echo 'wetbrush_studio_tests -functions failed (exit ${_wb_rc}): ${_wb_err}' >&2; exit 1")
  set_tests_properties(studio.list_functions PROPERTIES LABELS studio)
  return()
endif()
foreach(_wb_f IN LISTS _wb_functions)
  string(REPLACE "()" "" _wb_f "${_wb_f}")
  add_test(studio.${_wb_f} "${WB_XVFB_RUN}" -a -s "-screen 0 1600x1000x24" "${WB_STUDIO_TEST_EXE}" ${_wb_f})
  # RUN_SERIAL: the studio feeds pen samples to its simulation thread in real time, so a test
  # sharing the cores with other tests sees its strokes simulated in other batches. Passive
  # OpenMP waits: the simulation thread's team shares the cores with the UI and Mesa's llvmpipe.
  set_tests_properties(studio.${_wb_f} PROPERTIES LABELS studio TIMEOUT 300 RUN_SERIAL TRUE
    ENVIRONMENT "WB_DEVICE=cpu;OMP_WAIT_POLICY=passive")
endforeach()
