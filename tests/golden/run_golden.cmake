# Renders one golden scene and compares it with its reference.
#   cmake -DDRIFT=<drift> -DSCENE=<scene.toml> -DWORK=<dir> -DREFERENCE=<ref.exr>
#         [-DMODE=test|update|expect-fail] [-DEXTRA="--seed;99"] -P run_golden.cmake
# test:        render, then `drift compare` against the reference; fails if either fails.
# update:      render straight into the reference (written atomically by drift).
# expect-fail: render with EXTRA arguments (a deliberate change) and require
#              the comparison to FAIL: proves the tolerance is tight enough.
# The scene may use @DRIFT_SOURCE_DIR@ and @WORK@ in paths; they are substituted
# here, so scenes work whatever directory the renderer resolves relative paths
# against. A scene whose inputs are made by other stages lists those drift
# commands, one per line, in <name>.prepare next to it (same substitutions);
# they run first, so the golden image guards those stages too.
cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/golden_settings.cmake)
foreach(var DRIFT SCENE WORK REFERENCE)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_golden.cmake: -D${var}=... is required")
  endif()
endforeach()
if(NOT DEFINED MODE)
  set(MODE test)
endif()
get_filename_component(name ${SCENE} NAME_WE)
get_filename_component(source_dir ${CMAKE_CURRENT_LIST_DIR}/../.. ABSOLUTE)
set(DRIFT_SOURCE_DIR ${source_dir})

file(MAKE_DIRECTORY ${WORK})
get_filename_component(scene_dir ${SCENE} DIRECTORY)
if(EXISTS ${scene_dir}/${name}.prepare)
  file(STRINGS ${scene_dir}/${name}.prepare prepare_lines)
  foreach(line ${prepare_lines})
    if(line MATCHES "^[ \t]*(#|$)")
      continue()
    endif()
    string(CONFIGURE "${line}" line @ONLY)
    separate_arguments(args UNIX_COMMAND "${line}")
    message(STATUS "golden ${name}: prepare: drift ${line}")
    execute_process(COMMAND ${DRIFT} ${args} RESULT_VARIABLE rc OUTPUT_QUIET)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "golden ${name}: 'drift ${line}' failed (exit ${rc})")
    endif()
  endforeach()
endif()
file(READ ${SCENE} scene_text)
string(CONFIGURE "${scene_text}" scene_text @ONLY)
set(scene ${WORK}/${name}.toml)
file(WRITE ${scene} "${scene_text}")

if(MODE STREQUAL "update")
  set(image ${REFERENCE})
elseif(MODE STREQUAL "expect-fail")
  set(image ${WORK}/${name}_changed.exr)
else()
  set(image ${WORK}/${name}.exr)
endif()

set(render_cmd ${DRIFT} render ${scene} --size ${GOLDEN_SIZE} --spp ${GOLDEN_SPP} -o ${image}
               ${EXTRA})
message(STATUS "golden ${name}: ${render_cmd}")
execute_process(COMMAND ${render_cmd} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "golden ${name}: drift render failed (exit ${rc})")
endif()
if(MODE STREQUAL "update")
  message(STATUS "golden ${name}: reference written to ${REFERENCE}")
  return()
endif()

if(NOT EXISTS ${REFERENCE})
  message(FATAL_ERROR "golden ${name}: no reference ${REFERENCE}; run scripts/update-golden.sh")
endif()
get_filename_component(image_stem ${image} NAME_WE)
set(compare_cmd ${DRIFT} compare ${image} ${REFERENCE} --metric ${GOLDEN_METRIC}
                --threshold ${GOLDEN_THRESHOLD} --pixel-threshold ${GOLDEN_PIXEL_THRESHOLD}
                --fail-percent ${GOLDEN_FAIL_PERCENT} --diff ${WORK}/${image_stem}_diff.png)
message(STATUS "golden ${name}: ${compare_cmd}")
execute_process(COMMAND ${compare_cmd} RESULT_VARIABLE rc)
if(MODE STREQUAL "expect-fail")
  if(rc EQUAL 0)
    message(FATAL_ERROR "golden ${name}: a render changed by '${EXTRA}' still passed the "
                        "comparison; the tolerance is too loose to catch real changes")
  elseif(NOT rc EQUAL 1)
    message(FATAL_ERROR "golden ${name}: drift compare exited ${rc} (expected 1 = fail)")
  endif()
  message(STATUS "golden ${name}: the changed render fails as it should")
elseif(NOT rc EQUAL 0)
  message(FATAL_ERROR "golden ${name}: differs from its reference (diff: ${WORK}/${image_stem}_diff.png). "
                      "If the change is intended, run scripts/update-golden.sh and commit the references.")
endif()
