# cmc33_mpi_probe(<complete-var> <reason-var>): whether MPI's C++ compiler wrapper can compile a
# file that includes <mpi.h>. Debian's openmpi-bin (pulled in by VTK and ParaView) ships mpicxx
# without the headers of libopenmpi-dev; CMake's FindMPI then stops the whole configure, so the
# default build looks for MPI only when this probe passes. <reason-var> says why it did not.
function(cmc33_mpi_probe complete_var reason_var)
    set(${complete_var} OFF PARENT_SCOPE)
    if(MPI_CXX_COMPILER)
        set(_wrapper "${MPI_CXX_COMPILER}")
    else()
        find_program(CMC33_MPICXX NAMES mpicxx mpic++ mpiCC mpicxx.openmpi mpicxx.mpich
                     DOC "MPI's C++ compiler wrapper (only probed: see cmake/cmc33_mpi_probe.cmake)")
        if(NOT CMC33_MPICXX)
            set(${reason_var} "no MPI C++ compiler wrapper (mpicxx) found; Debian: libopenmpi-dev" PARENT_SCOPE)
            return()
        endif()
        set(_wrapper "${CMC33_MPICXX}")
    endif()
    set(_dir "${CMAKE_BINARY_DIR}/CMakeFiles/cmc33_mpi_probe")
    file(WRITE "${_dir}/probe.cpp" "#include <mpi.h>\nint main() { return MPI_SUCCESS; }\n")
    execute_process(COMMAND "${_wrapper}" -E "${_dir}/probe.cpp" -o "${_dir}/probe.i"
                    RESULT_VARIABLE _result OUTPUT_QUIET ERROR_VARIABLE _error TIMEOUT 60)
    if(NOT _result EQUAL 0)
        # the first line of the compiler's complaint (e.g. "mpi.h: No such file or directory")
        string(REGEX MATCH "[^\n]*(error|Error|ERROR)[^\n]*" _first "${_error}")
        string(REGEX REPLACE "^.*(fatal )?error: *" "" _first "${_first}")
        string(STRIP "${_first}" _first)
        if(_first STREQUAL "")
            set(_first "exit status ${_result}")
        endif()
        get_filename_component(_name "${_wrapper}" NAME)
        set(${reason_var} "MPI is incomplete: ${_name} cannot compile #include <mpi.h> (${_first}); Debian: libopenmpi-dev"
            PARENT_SCOPE)
        return()
    endif()
    set(${complete_var} ON PARENT_SCOPE)
endfunction()
