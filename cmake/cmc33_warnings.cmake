# cmc33_set_warnings(target): the warning set every target of the project builds with.
function(cmc33_set_warnings target)
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wshadow -Wpedantic -Wnon-virtual-dtor
                                             -Wcast-align -Wnull-dereference -Wdouble-promotion)
    # g++ 12 reports -Wrestrict inside std::string's own code at -O2/-O3 (GCC bug 105329, a
    # false positive fixed in g++ 13); it says nothing about ours.
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
        target_compile_options(${target} PRIVATE -Wno-restrict)
    endif()
    if(CMC33_WERROR)
        target_compile_options(${target} PRIVATE -Werror)
    endif()
endfunction()
