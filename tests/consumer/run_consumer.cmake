# Installs the build tree into a scratch prefix, then configures, builds and runs the consumer
# project against it with find_package(vrdeform); VARIANT sim_only asks for the solver alone.
# Run by CTest with -P.
file(REMOVE_RECURSE "${WORK_DIR}")
set(sim_only OFF)
if(VARIANT STREQUAL "sim_only")
  set(sim_only ON)
endif()
function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message("${out}")
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "failed (${result}): ${ARGV}\n${err}")
  endif()
endfunction()
run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}" -B "${WORK_DIR}/build" -G "${GENERATOR}" -DCMAKE_BUILD_TYPE=Release
    "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix" "-DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS}"
    "-DVRDEFORM_SIM_ONLY=${sim_only}")
run(${CMAKE_COMMAND} --build "${WORK_DIR}/build")
run("${WORK_DIR}/build/consumer")
