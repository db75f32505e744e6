# Builds and runs tests/package/consumer against cmc33 (cmake -P):
#   -DMODE=package      -DCMC33_BUILD=<cmc33 build tree> -DWORK=<scratch folder>: installs the build
#                       tree into WORK/prefix, then builds the consumer with find_package(cmc33)
#   -DMODE=subdirectory -DCMC33_SOURCE=<cmc33 source tree> -DWORK=<scratch folder>
# Also needs -DSOURCE=<this folder> and -DGENERATOR=<CMake generator>.
# The two modes that compile the library again do it unoptimised (the test is the build's shape,
# not its speed): half the compile time of Release.
set(unoptimised -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG=-O0)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
function(run)
    execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
        string(REPLACE ";" " " line "${ARGN}")
        message(FATAL_ERROR "failed (${rc}): ${line}")
    endif()
endfunction()
if(MODE STREQUAL "shared")
    # the library built again as shared libraries (hidden symbols, the API exported), installed
    run(${CMAKE_COMMAND} -S ${CMC33_SOURCE} -B ${WORK}/library -G ${GENERATOR} ${unoptimised}
        -DBUILD_SHARED_LIBS=ON -DCMC33_BUILD_CLI=OFF -DCMC33_BUILD_TESTS=OFF)
    run(${CMAKE_COMMAND} --build ${WORK}/library -j2)
    run(${CMAKE_COMMAND} --install ${WORK}/library --prefix ${WORK}/prefix)
    run(${CMAKE_COMMAND} -S ${SOURCE}/consumer -B ${WORK}/build -G ${GENERATOR} ${unoptimised}
        -DCMC33_CONSUME=package -DCMAKE_PREFIX_PATH=${WORK}/prefix)
elseif(MODE STREQUAL "package")
    run(${CMAKE_COMMAND} --install ${CMC33_BUILD} --prefix ${WORK}/prefix)
    run(${CMAKE_COMMAND} -S ${SOURCE}/consumer -B ${WORK}/build -G ${GENERATOR} -DCMAKE_BUILD_TYPE=Release
        -DCMC33_CONSUME=package -DCMAKE_PREFIX_PATH=${WORK}/prefix)
else()
    run(${CMAKE_COMMAND} -S ${SOURCE}/consumer -B ${WORK}/build -G ${GENERATOR} ${unoptimised}
        -DCMC33_CONSUME=subdirectory -DCMC33_SOURCE_DIR=${CMC33_SOURCE})
endif()
run(${CMAKE_COMMAND} --build ${WORK}/build -j2)
run(${WORK}/build/consumer)
run(${WORK}/build/core_only)
