#pragma once
// A pool of worker threads that stay alive between calls, for passes of a few milliseconds.
//
// Why: a std::thread started for each pass begins on the CPU of the thread that started it and
// waits there until the scheduler moves it; on a 2-core machine a 2-thread extraction of a
// 256^3 volume (about 4 ms of work a thread) ran no faster than one thread. A worker that sleeps
// between jobs wakes on the CPU it last ran on, which is idle, and starts at once.
//
// One job at a time: a caller that finds the pool busy (another thread's extraction, or a task of
// the pool itself starting a nested job) gets false from try_run() and runs its tasks on threads
// of its own, as before. After fork() the child has none of the parent's workers: it never uses
// the pool either.

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include <unistd.h>

namespace cmc33::detail {

class ThreadPool {
public:
    /// The process's pool (workers are started on first use, as many as jobs ask for, at most
    /// kMaxWorkers).
    static ThreadPool& instance()
    {
        static ThreadPool pool;
        return pool;
    }

    /// Runs task(0), ..., task(n - 1), each once, on the calling thread and up to n - 1 workers;
    /// returns when all have returned. Tasks must not throw. False (and nothing run) when the pool
    /// is busy or cannot be used in this process.
    bool try_run(int n, const std::function<void(int)>& task)
    {
        if (n <= 1 || getpid() != owner_) return false;
        std::unique_lock job(busy_, std::try_to_lock);
        if (!job.owns_lock()) return false;
        const int helpers = std::min(n - 1, kMaxWorkers);
        {
            std::lock_guard lock(mutex_);
            try {
                while (static_cast<int>(workers_.size()) < helpers) {
                    workers_.emplace_back([this, index = static_cast<int>(workers_.size())] { work(index); });
                }
            } catch (...) {
                // no more threads: go on with those there are
            }
            task_ = &task;
            tasks_ = n;
            next_.store(0, std::memory_order_relaxed);
            wanted_ = std::min<int>(helpers, static_cast<int>(workers_.size()));
            joined_ = left_ = 0;
            ++generation_;
        }
        wake_.notify_all();
        take_tasks(task);
        std::unique_lock lock(mutex_);
        // Every task has been taken, by this thread or by a worker that joined: the workers not
        // yet awake are not waited for (a sleeping CPU can take milliseconds to wake on a VM,
        // longer than the whole job of a small volume); they find the job full when they wake.
        wanted_ = joined_;
        done_.wait(lock, [this] { return left_ == wanted_; });
        task_ = nullptr;
        return true;
    }

    ThreadPool(const ThreadPool&) = delete;
    ThreadPool& operator=(const ThreadPool&) = delete;

    ~ThreadPool()
    {
        {
            std::lock_guard lock(mutex_);
            stop_ = true;
        }
        wake_.notify_all();
        for (std::thread& t : workers_) {
            if (t.joinable()) t.join();
        }
    }

private:
    static constexpr int kMaxWorkers = 1023; // extract() takes at most 1024 threads

    ThreadPool() : owner_(getpid()) {}

    /// Takes the job's task indices until none is left.
    void take_tasks(const std::function<void(int)>& task)
    {
        for (int t = next_.fetch_add(1, std::memory_order_relaxed); t < tasks_; t = next_.fetch_add(1, std::memory_order_relaxed)) {
            task(t);
        }
    }

    void work(int /*index*/)
    {
        std::uint64_t seen = 0;
        std::unique_lock lock(mutex_);
        for (;;) {
            wake_.wait(lock, [&] { return stop_ || (generation_ != seen); });
            if (stop_) return;
            seen = generation_;
            if (joined_ >= wanted_) continue; // this job has the workers it asked for
            ++joined_;
            const std::function<void(int)>& task = *task_;
            lock.unlock();
            take_tasks(task);
            lock.lock();
            if (++left_ == wanted_) done_.notify_one();
        }
    }

    const pid_t owner_;
    std::mutex busy_;  ///< held by the caller of the running job
    std::mutex mutex_; ///< guards everything below
    std::condition_variable wake_, done_;
    std::vector<std::thread> workers_;
    std::uint64_t generation_ = 0;
    const std::function<void(int)>* task_ = nullptr;
    int tasks_ = 0, wanted_ = 0, joined_ = 0, left_ = 0;
    std::atomic<int> next_{0};
    bool stop_ = false;
};

} // namespace cmc33::detail
