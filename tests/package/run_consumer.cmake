# Builds and runs tests/package/consumer against cmc33 (cmake -P):
#   -DMODE=package -DCMC33_BUILD=<cmc33 build tree> -DWORK=<scratch folder>: installs the build tree
#                  into WORK/prefix, then builds the consumer with find_package(cmc33)
#   -DMODE=shared  -DCMC33_SOURCE=<cmc33 source tree> -DWORK=<scratch folder>: builds the consumer
#                  with the source tree added by add_subdirectory and BUILD_SHARED_LIBS=ON (the
#                  library as shared libraries: hidden symbols, the API exported), runs it, then
#                  installs that same build of the library into WORK/prefix and builds and runs a
#                  second consumer with find_package(cmc33): both ways of consuming the source, and
#                  the shared package, for one compile of the library
# Also needs -DSOURCE=<this folder> and -DGENERATOR=<CMake generator>. Each consumer prints how it
# got cmc33::core (package or subdirectory, and the library's type); the test's regular
# expressions check those lines.
# The shared mode compiles the library again, unoptimised (the test is the build's shape, not its
# speed): half the compile time of Release.
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
# Configures the consumer in `build` with the remaining arguments, builds it and runs both programs.
function(consume build)
    run(${CMAKE_COMMAND} -S ${SOURCE}/consumer -B ${build} -G ${GENERATOR} ${ARGN})
    run(${CMAKE_COMMAND} --build ${build} -j2)
    run(${build}/consumer)
    run(${build}/core_only)
endfunction()
if(MODE STREQUAL "shared")
    consume(${WORK}/subdirectory ${unoptimised} -DCMC33_CONSUME=subdirectory -DCMC33_SOURCE_DIR=${CMC33_SOURCE}
            -DBUILD_SHARED_LIBS=ON)
    # the library's binary folder inside the consumer's build (add_subdirectory(... cmc33)): its
    # install rules alone, the consumer has none
    run(${CMAKE_COMMAND} --install ${WORK}/subdirectory/cmc33 --prefix ${WORK}/prefix)
    consume(${WORK}/package ${unoptimised} -DCMC33_CONSUME=package -DCMAKE_PREFIX_PATH=${WORK}/prefix)
elseif(MODE STREQUAL "package")
    run(${CMAKE_COMMAND} --install ${CMC33_BUILD} --prefix ${WORK}/prefix)
    consume(${WORK}/build -DCMAKE_BUILD_TYPE=Release -DCMC33_CONSUME=package -DCMAKE_PREFIX_PATH=${WORK}/prefix)
else()
    message(FATAL_ERROR "failed (MODE): MODE is package or shared, not \"${MODE}\"")
endif()
