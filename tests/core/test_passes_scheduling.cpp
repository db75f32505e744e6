// The passes of passes.hpp as they are scheduled: progress and cancellation, the caller's
// executor, the shared thread pool, the thread-count rule, and plan_ranges / run_ranges / lay_out
// composing extract()'s mesh for every plan.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/passes.hpp"
#include "cmc33/threads.hpp"
#include "parallel.hpp"
#include "passes_fields.hpp"
#include "thread_pool.hpp"

namespace {

using cmc33::ExtractOptions;
using cmc33::MeshSpans;
using cmc33::RangeCounts;
using cmc33::Volume;
using cmc33::test::bucky;
using cmc33::test::noise;

TEST(Passes, ProgressRisesToOneAndCancellingThrows)
{
    const Volume v = noise({64, 64, 96}, 3);
    for (const int threads : {1, 2}) {
        std::vector<double> seen;
        std::mutex m;
        ExtractOptions opt;
        opt.threads = threads;
        opt.progress = [&](double f) {
            const std::lock_guard lock(m);
            seen.push_back(f);
            return true;
        };
        const cmc33::Mesh mesh = cmc33::extract(v, 0.0, opt);
        ASSERT_GE(seen.size(), 2u) << "the first plane reports at once, the end with 1";
        EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
        EXPECT_GE(seen.front(), 0.0);
        EXPECT_EQ(seen.back(), 1.0);
        opt.progress = nullptr;
        EXPECT_EQ(cmc33::extract(v, 0.0, opt).triangles, mesh.triangles) << "progress changes nothing";

        int calls = 0;
        opt.progress = [&](double) { return ++calls < 2; };
        try {
            (void)cmc33::extract(v, 0.0, opt);
            FAIL() << "not cancelled";
        } catch (const cmc33::Error& e) {
            EXPECT_EQ(e.status(), cmc33::Status::cancelled) << e.what();
        }
        EXPECT_EQ(calls, 2) << "no call after the one that stopped the work";
    }
}

TEST(Passes, TheCallersExecutorRunsTheTasks)
{
    const Volume v = bucky();
    ExtractOptions opt;
    opt.threads = 4;
    const cmc33::Mesh expected = cmc33::extract(v, 100.5, opt);
    int batches = 0, tasks = 0;
    opt.executor = [&](int n, const std::function<void(int)>& task) {
        ++batches;
        for (int t = n - 1; t >= 0; --t, ++tasks) task(t); // reversed: order must not matter
    };
    const cmc33::Mesh m = cmc33::extract(v, 100.5, opt);
    EXPECT_EQ(batches, 2); // count, then emit
    EXPECT_EQ(tasks, 8);
    EXPECT_EQ(m.positions, expected.positions);
    EXPECT_EQ(m.triangles, expected.triangles);
    // an exception from the caller's side reaches the caller unchanged
    opt.executor = [](int, const std::function<void(int)>&) { throw std::runtime_error("pool is shut down"); };
    EXPECT_THROW((void)cmc33::extract(v, 100.5, opt), std::runtime_error);
}

TEST(Passes, ConcurrentAndNestedCallsShareThePoolOrStartTheirOwnThreads)
{
    // The default executor is a process-wide pool (support/thread_pool.hpp). Calls from several
    // threads at once, and a call from inside another call's task, find it busy and run on
    // threads of their own: the same meshes, no deadlock.
    const Volume v = noise({40, 36, 48}, 11);
    ExtractOptions opt;
    opt.threads = 3;
    opt.normals = true;
    const cmc33::Mesh expected = cmc33::extract(v, 0.0, opt);
    std::vector<std::thread> callers;
    std::atomic<int> same{0};
    for (int c = 0; c < 4; ++c) {
        callers.emplace_back([&] {
            for (int r = 0; r < 5; ++r) {
                const cmc33::Mesh m = cmc33::extract(v, 0.0, opt);
                same += m.triangles == expected.triangles && m.normals == expected.normals;
            }
        });
    }
    for (std::thread& t : callers) t.join();
    EXPECT_EQ(same.load(), 20);

    // nested: each of the outer call's tasks (run by the pool) extracts with threads of its own
    std::atomic<int> nested_same{0};
    ExtractOptions outer = opt;
    outer.progress = [&](double) {
        nested_same += cmc33::extract(v, 0.0, opt).triangles == expected.triangles;
        return true;
    };
    EXPECT_EQ(cmc33::extract(v, 0.0, outer).triangles, expected.triangles);
    EXPECT_GE(nested_same.load(), 1);
}

TEST(Passes, PoolRunsEveryTaskOnceAndLeavesNoWorkerInAFinishedJob)
{
    // The caller of a job does not wait for workers still asleep once every task is taken; a
    // worker that wakes late must then stay out of that job (its task and counters end with the
    // loop's iteration, so ASan and TSan see a late access; the pool's count of those that left
    // would never match and the caller would hang) and still join the next ones. Jobs of 2 to 5
    // tasks back to back, most too short for a worker to wake in time.
    cmc33::detail::ThreadPool& pool = cmc33::detail::ThreadPool::instance();
    int worker_tasks = 0;
    for (int job = 0; job < 3000; ++job) {
        const int n = 2 + job % 4;
        std::vector<std::atomic<int>> runs(static_cast<std::size_t>(n));
        std::atomic<int> off_caller{0};
        const std::thread::id caller = std::this_thread::get_id();
        const std::function<void(int)> task = [&](int t) {
            runs[static_cast<std::size_t>(t)].fetch_add(1);
            if (std::this_thread::get_id() != caller) off_caller.fetch_add(1);
            if (job % 100 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2)); // let workers join
        };
        ASSERT_TRUE(pool.try_run(n, task));
        for (int t = 0; t < n; ++t) ASSERT_EQ(runs[static_cast<std::size_t>(t)].load(), 1) << "job " << job << " task " << t;
        worker_tasks += off_caller.load();
    }
    EXPECT_GT(worker_tasks, 0); // the workers did take part
}

TEST(Passes, ThreadCountIsTheRequestOrEveryCoreAndAtMostOnePerPiece)
{
    EXPECT_EQ(cmc33::thread_count(3), 3);
    const int all = cmc33::thread_count(0);
    EXPECT_GE(all, 1);
    EXPECT_EQ(cmc33::thread_count(-2), all);
    EXPECT_EQ(cmc33::detail::threads_for(8, 3), 3);
    EXPECT_EQ(cmc33::detail::threads_for(2, 100), 2);
    EXPECT_EQ(cmc33::detail::threads_for(5, 0), 1);
    EXPECT_EQ(cmc33::detail::threads_for(0, std::int64_t{1} << 40), all);
}

TEST(Passes, PlanRunLayOutAndEmitGiveExtractsMeshForEveryPlan)
{
    const Volume v = noise({20, 17, 40}, 11);
    const ExtractOptions opt{.normals = true, .threads = 1};
    const cmc33::Mesh expected = cmc33::extract(v, 0.1, opt);
    const std::int64_t plane = 20 * 17;
    v.visit([&](auto g) {
        EXPECT_EQ(cmc33::plan_ranges(g, 1).ranges(), 1) << "one thread: one range";
        EXPECT_EQ(cmc33::plan_ranges(g, 4).ranges(), 5) << "threads: about nz / 8 ranges, at least one per thread";
        EXPECT_EQ(cmc33::plan_ranges(g, 2).ranges(), 5);
        EXPECT_EQ(cmc33::plan_ranges(g, 3).ranges(), 5);
        EXPECT_EQ(cmc33::plan_ranges(g, 7).ranges(), 7);
        for (const int threads : {1, 3, 64}) {
            for (const std::int64_t samples : {std::int64_t{0}, std::int64_t{1}, 5 * plane, 7 * plane + 3}) {
                const std::string what = std::to_string(threads) + " threads, ranges of " + std::to_string(samples) + " samples";
                const cmc33::RangePlan plan = cmc33::plan_ranges(g, threads, samples);
                EXPECT_EQ(plan.threads, std::min(threads, 40)) << what;
                EXPECT_EQ(plan.window_planes, 0) << what;
                ASSERT_GE(plan.ranges(), 1) << what;
                EXPECT_EQ(plan.first_planes.front(), 0) << what;
                EXPECT_EQ(plan.first_planes.back(), 40) << what;
                for (int r = 0; r < plan.ranges(); ++r) {
                    const std::int64_t planes = plan.first_planes[static_cast<std::size_t>(r) + 1] - plan.first_planes[static_cast<std::size_t>(r)];
                    EXPECT_GE(planes, 1) << what;
                    if (samples > 0) {
                        EXPECT_LE(planes * plane, std::max(samples, plane)) << what;
                    }
                }
                const auto k = [&plan](int r) { return plan.first_planes[static_cast<std::size_t>(r)]; };
                std::vector<int> order(static_cast<std::size_t>(plan.ranges()));
                std::iota(order.begin(), order.end(), 0);
                std::vector<RangeCounts> counts(order.size());
                cmc33::run_ranges(plan.threads, order, [&](int r, int) {
                    counts[static_cast<std::size_t>(r)] = cmc33::count(g, 0.1, opt, k(r), k(r + 1));
                });
                const cmc33::MeshLayout layout = cmc33::lay_out(counts);
                ASSERT_EQ(layout.vertex_count, static_cast<std::int64_t>(expected.vertex_count())) << what;
                ASSERT_EQ(layout.triangle_count, static_cast<std::int64_t>(expected.triangle_count())) << what;
                cmc33::Mesh m;
                m.positions.resize(expected.positions.size());
                m.normals.resize(expected.normals.size());
                m.triangles.resize(expected.triangles.size());
                cmc33::run_ranges(plan.threads, cmc33::emit_order(counts), [&](int r, int) {
                    MeshSpans out;
                    out.positions = m.positions.data();
                    out.normals = m.normals.data();
                    out.triangles = m.triangles.data();
                    const auto i = static_cast<std::size_t>(r);
                    cmc33::emit(g, 0.1, opt, counts[i], layout.offsets[i], out);
                });
                EXPECT_EQ(m.positions, expected.positions) << what;
                EXPECT_EQ(m.normals, expected.normals) << what;
                EXPECT_EQ(m.triangles, expected.triangles) << what;
            }
        }
    });
}

TEST(Passes, RunRangesRunsEachRangeOnceRethrowsTheLowestErrorAndStops)
{
    std::vector<int> order(50);
    std::iota(order.rbegin(), order.rend(), 0); // 49 first
    for (const int threads : {1, 4}) {
        std::vector<std::atomic<int>> runs(order.size());
        std::atomic<int> bad_task{0};
        cmc33::run_ranges(threads, order, [&](int r, int task) {
            runs[static_cast<std::size_t>(r)].fetch_add(1);
            if (task < 0 || task >= threads) bad_task.fetch_add(1);
        });
        for (std::size_t r = 0; r < runs.size(); ++r) EXPECT_EQ(runs[r].load(), 1) << threads << " threads, range " << r;
        EXPECT_EQ(bad_task.load(), 0);

        // ranges 30 and 7 throw: 7's error, though 30 comes first in the order
        try {
            cmc33::run_ranges(threads, order, [](int r, int) {
                if (r == 30 || r == 7) throw std::runtime_error("range " + std::to_string(r));
            });
            ADD_FAILURE() << "no error";
        } catch (const std::runtime_error& e) {
            EXPECT_EQ(std::string(e.what()), "range 7");
        }

        // progress says stop at its first call: Error{cancelled}; on one thread no range starts after it
        std::atomic<int> ran{0};
        std::vector<double> seen;
        try {
            cmc33::run_ranges(threads, order, [&](int, int) { ran.fetch_add(1); }, [&](double f) {
                seen.push_back(f);
                return false;
            });
            ADD_FAILURE() << "not cancelled";
        } catch (const cmc33::Error& e) {
            EXPECT_EQ(e.status(), cmc33::Status::cancelled) << e.what();
        }
        ASSERT_FALSE(seen.empty());
        EXPECT_GT(seen[0], 0.0);
        if (threads == 1) { // with more, the others may take every (empty) range before the stop lands
            EXPECT_EQ(ran.load(), 1);
        }

        // the caller's executor runs the tasks
        int batches = 0;
        std::vector<int> taken;
        cmc33::run_ranges(
            threads, order, [&](int r, int) { taken.push_back(r); }, {},
            [&](int n, const std::function<void(int)>& task) {
                ++batches;
                for (int t = 0; t < n; ++t) task(t); // one after the other: the first takes every range
            });
        EXPECT_EQ(batches, 1);
        EXPECT_EQ(taken, order);
    }
}

} // namespace
