#pragma once
// A deterministic parallel loop: [0, n) cut into contiguous chunks, one per thread. Results that
// depend on the thread count never leave a pass: every pass writes at offsets fixed beforehand.

#include <algorithm>
#include <cstdint>
#include <exception>
#include <thread>
#include <vector>

#include "cmc33/threads.hpp"

namespace cmc33::detail {

/// The threads for `items` pieces of work (sample planes, fields, labels): thread_count(requested)
/// (cmc33/threads.hpp), at most `items` and at least 1.
inline int threads_for(int requested, std::int64_t items) noexcept
{
    return static_cast<int>(std::clamp<std::int64_t>(thread_count(requested), 1, std::max<std::int64_t>(items, 1)));
}

/// Calls body(thread_index, begin, end) on `threads` contiguous chunks of [0, n).
template <class Body> void parallel_chunks(std::int64_t n, int threads, Body&& body)
{
    threads = static_cast<int>(std::max<std::int64_t>(1, std::min<std::int64_t>(threads, n)));
    if (threads == 1) {
        body(0, std::int64_t{0}, n);
        return;
    }
    std::vector<std::thread> pool;
    std::vector<std::exception_ptr> errors(static_cast<std::size_t>(threads));
    for (int t = 0; t < threads; ++t) {
        const std::int64_t begin = n * t / threads, end = n * (t + 1) / threads;
        pool.emplace_back([&, t, begin, end] {
            try {
                body(t, begin, end);
            } catch (...) {
                errors[static_cast<std::size_t>(t)] = std::current_exception();
            }
        });
    }
    for (auto& th : pool) th.join();
    for (auto& e : errors) {
        if (e) std::rethrow_exception(e);
    }
}

} // namespace cmc33::detail
