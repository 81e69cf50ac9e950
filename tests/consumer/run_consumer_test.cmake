# Installs the built Drape into a private prefix, then configures and builds the consumer
# project (tests/consumer) and Drape's dressing example against it with find_package(Drape),
# without Drape's compile options (no -march=native), and runs both. The consumer dresses
# CHARACTER, a shared third-party character outside the project: when it is missing, the
# run is skipped (the builds are still checked).
file(REMOVE_RECURSE "${WORK_DIR}")
execute_process(COMMAND ${CMAKE_COMMAND} --install "${DRAPE_BINARY_DIR}" --prefix "${WORK_DIR}/prefix"
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "install of Drape into ${WORK_DIR}/prefix failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S "${CONSUMER_SOURCE_DIR}" -B "${WORK_DIR}/build"
                        -DCMAKE_BUILD_TYPE=${BUILD_TYPE} -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix
                        -DDRESS_EXAMPLE=${DRESS_EXAMPLE}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the consumer with find_package(Drape) failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build "${WORK_DIR}/build" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the consumer and the dressing example against Drape::drape failed")
endif()
execute_process(COMMAND "${WORK_DIR}/build/dress_example" "" "" 30 RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the dressing example built against the package ran but failed (exit ${rc})")
endif()
if(NOT EXISTS "${CHARACTER}")
  message("SKIPPED: the shared character ${CHARACTER} is not there; the consumer was built but not run")
  return()
endif()
execute_process(COMMAND "${WORK_DIR}/build/my_game" "${CHARACTER}" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the consumer ran but failed (exit ${rc})")
endif()
