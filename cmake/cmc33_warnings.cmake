# cmc33_set_warnings(target): the warning set every target of the project builds with.
function(cmc33_set_warnings target)
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wshadow -Wpedantic -Wnon-virtual-dtor
                                             -Wcast-align -Wnull-dereference -Wdouble-promotion)
    if(CMC33_WERROR)
        target_compile_options(${target} PRIVATE -Werror)
    endif()
endfunction()
