# cmake -DSOURCE_DIR=... -P file_lengths.cmake: fails naming every hand-written source file of more
# than 900 lines (CONTRIBUTING.md: a file that grows past it is cut along what it does). Generated
# tables are exempt: they are written by tools/ and kept current by a test.
cmake_minimum_required(VERSION 3.25)
set(limit 900)
set(exempt "src/tables/mc33_tables.cpp")
file(GLOB_RECURSE files RELATIVE ${SOURCE_DIR}
     ${SOURCE_DIR}/src/*.cpp ${SOURCE_DIR}/src/*.hpp ${SOURCE_DIR}/include/*.hpp
     ${SOURCE_DIR}/cli/*.cpp ${SOURCE_DIR}/cli/*.hpp ${SOURCE_DIR}/mpi/*.cpp ${SOURCE_DIR}/mpi/*.hpp
     ${SOURCE_DIR}/python/*.cpp ${SOURCE_DIR}/python/*.hpp ${SOURCE_DIR}/python/*.py
     ${SOURCE_DIR}/tests/*.cpp ${SOURCE_DIR}/tests/*.hpp ${SOURCE_DIR}/tests/*.py
     ${SOURCE_DIR}/fuzz/*.cpp ${SOURCE_DIR}/bench/*.cpp ${SOURCE_DIR}/bench/*.py
     ${SOURCE_DIR}/tools/*.py ${SOURCE_DIR}/web/*.js ${SOURCE_DIR}/web/*.html)
set(long "")
foreach(f IN LISTS files)
    if(f IN_LIST exempt OR f MATCHES "(^|/)(build|node_modules)[^/]*/")
        continue()
    endif()
    file(STRINGS ${SOURCE_DIR}/${f} lines)
    list(LENGTH lines n)
    if(n GREATER limit)
        list(APPEND long "${f} (${n})")
    endif()
endforeach()
if(long)
    list(JOIN long ", " text)
    message(FATAL_ERROR "source files over ${limit} lines: ${text}")
endif()
list(LENGTH files count)
message(STATUS "${count} source files, none over ${limit} lines")
