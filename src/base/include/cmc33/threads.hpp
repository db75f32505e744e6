#pragma once
/// @file threads.hpp
/// The library's one rule for a `threads` option (ExtractOptions::threads and every other one).

#include <thread>

namespace cmc33 {

/// The number of threads a `threads` option asks for: `requested` when positive, else (0 or
/// less) every core the machine reports, at least 1. A WebAssembly build without pthreads has
/// one thread, whatever is asked. Every function of the library with a `threads` option starts
/// this many threads at most, and never more than it has pieces of work (sample planes, fields,
/// labels); results never depend on the count.
inline int thread_count(int requested) noexcept
{
#if defined(__EMSCRIPTEN__) && !defined(__EMSCRIPTEN_PTHREADS__)
    (void)requested;
    return 1;
#else
    if (requested > 0) return requested;
    const unsigned cores = std::thread::hardware_concurrency();
    return cores == 0 ? 1 : static_cast<int>(cores);
#endif
}

} // namespace cmc33
