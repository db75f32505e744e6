#pragma once
// Scheduling of the passes: ranges of sample planes handed to tasks on the caller's executor or the
// process's worker pool, each task taking the next range when free, with progress ticks and
// cancellation shared by all of them.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "thread_pool.hpp"

namespace cmc33::detail {

/// Progress over the planes of both passes, shared by extract()'s tasks: every task ticks once per
/// plane; whoever ticks when no other task is reporting, and at least kInterval after the last
/// report, calls the caller's callback. A false answer stops every task at its next plane.
class Ticker {
public:
    Ticker(const Progress& progress, std::int64_t total) : progress_(progress), total_(std::max<std::int64_t>(total, 1)) {}
    /// One plane done; false when the work is to stop.
    bool tick()
    {
        done_.fetch_add(1, std::memory_order_relaxed);
        if (!progress_) return true;
        if (cancelled_.load(std::memory_order_relaxed)) return false;
        std::unique_lock lock(mutex_, std::try_to_lock);
        if (!lock.owns_lock()) return true;
        const auto now = std::chrono::steady_clock::now();
        if (now - last_ < kInterval) return true;
        last_ = now;
        // read under the lock, so that the reported fractions never decrease
        const std::int64_t done = std::min(done_.load(std::memory_order_relaxed), total_);
        if (!progress_(static_cast<double>(done) / static_cast<double>(total_))) {
            cancelled_.store(true, std::memory_order_relaxed);
        }
        return !cancelled_.load(std::memory_order_relaxed);
    }
    bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }
    /// The final call, with 1 (not if the caller already stopped the work).
    void finish()
    {
        if (progress_ && !cancelled() && !progress_(1.0)) cancelled_.store(true, std::memory_order_relaxed);
    }

private:
    static constexpr std::chrono::milliseconds kInterval{20};
    const Progress& progress_;
    std::int64_t total_;
    std::atomic<std::int64_t> done_{0};
    std::atomic<bool> cancelled_{false};
    std::mutex mutex_;
    std::chrono::steady_clock::time_point last_{};
};

[[noreturn]] inline void throw_cancelled()
{
    throw Error(Status::cancelled, "extraction cancelled by the progress callback");
}

/// Runs task(0..n-1) on the caller's executor, or on the calling thread and the process's worker
/// pool (support/thread_pool.hpp), or when that is busy on one std::thread each (the first on the
/// calling thread); rethrows the first task's exception (by task index) once all have ended, so
/// the error does not depend on the executor's scheduling.
template <class Task> void run_tasks(int n, const Executor& executor, Task&& task)
{
    std::vector<std::exception_ptr> errors(static_cast<std::size_t>(n));
    const std::function<void(int)> guarded = [&](int t) {
        try {
            task(t);
        } catch (...) {
            errors[static_cast<std::size_t>(t)] = std::current_exception();
        }
    };
    if (executor) {
        executor(n, guarded);
    } else if (n == 1) {
        guarded(0);
    } else if (!detail::ThreadPool::instance().try_run(n, guarded)) {
        std::vector<std::thread> pool;
        pool.reserve(static_cast<std::size_t>(n - 1));
        try {
            for (int t = 1; t < n; ++t) pool.emplace_back(guarded, t);
        } catch (...) {
            for (auto& th : pool) th.join();
            throw Error(Status::too_large, "cannot start " + std::to_string(n) + " threads");
        }
        guarded(0);
        for (auto& th : pool) th.join();
    }
    for (auto& e : errors) {
        if (e) std::rethrow_exception(e);
    }
}

/// Runs work(r, t) for every range r of `order` (a permutation of 0..ranges-1) on n tasks t of
/// run_tasks, each taking the next range of `order` not yet taken, until none is left or the
/// ticker says stop; rethrows the error of the lowest range that failed, so that the error does
/// not depend on which thread ran which range.
template <class Work>
void for_each_range(int n, std::span<const int> order, const Executor& executor, const Ticker& ticker, Work&& work)
{
    const int ranges = static_cast<int>(order.size());
    std::vector<std::exception_ptr> errors(order.size());
    std::atomic<int> next{0};
    run_tasks(n, executor, [&](int task) {
        for (int taken = next.fetch_add(1); taken < ranges && !ticker.cancelled(); taken = next.fetch_add(1)) {
            const int r = order[static_cast<std::size_t>(taken)];
            try {
                work(r, task);
            } catch (...) {
                errors[static_cast<std::size_t>(r)] = std::current_exception();
            }
        }
    });
    for (auto& e : errors) {
        if (e) std::rethrow_exception(e);
    }
}

} // namespace cmc33::detail
