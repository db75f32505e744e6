#pragma once
// What verify() and the CLI's dataset check (cli/dataset, `cmc33 verify --dataset`) share: the
// parallel loop with its progress ticks, the per-thread tallies, and the failure records written
// at the end. Not installed; the functions the CLI calls are exported (CMC33_VERIFY_EXPORT) so
// that a shared library still offers them to it, as io's atomic_file.hpp does.

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cmc33/mesh.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"
#include "cmc33/verify_export.hpp"
#include "cmc33/volume.hpp"

namespace cmc33::verification::detail {

/// Subcases whose tiling depends on a face or interior test: the names with a dot (3.1 ... 13.5.2).
CMC33_VERIFY_EXPORT bool is_ambiguous_subcase(int subcase) noexcept;

/// One mismatching (field, method) pair, kept until the end of the run.
struct Failure {
    std::int64_t order = 0; ///< position of the field in the run: failures are kept in this order
    std::string name;       ///< file stem: "cell-000042"
    FieldKind kind = FieldKind::grid;
    std::shared_ptr<const Volume> volume;
    double iso = 0;
    FieldTopology expected;
    std::optional<MeshTopology> got; ///< none if there is no mesh (error)
    std::optional<Mesh> mesh;
    std::string subcases; ///< "13.5.2" for a cell, "6.1.2,13.1" for a grid
    std::string note;     ///< why there is no mesh, or what the command printed
};

/// Counts of one method on one thread; merged in a fixed order at the end.
struct Tally {
    MethodReport report;
    std::vector<Failure> failures; ///< at most 2 * max_failures between trims
};

/// One (field, method) comparison.
struct Outcome {
    FieldKind kind = FieldKind::grid;
    std::int64_t order = 0; ///< see Failure
    std::string name;       ///< see Failure
    std::shared_ptr<const Volume> volume;
    double iso = 0;
    const FieldTopology* expected = nullptr;
    std::optional<Mesh> mesh; ///< none: the extraction failed, `note` says why
    std::string note;
    std::vector<int> subcases; ///< the subcases the field counts for
};

/// Adds the comparison to `tally` and, on a mismatch, keeps the failure if it may be among the
/// first max_failures. Returns true if the mesh matched.
CMC33_VERIFY_EXPORT bool record(Tally& tally, Outcome&& outcome, int max_failures);

/// @throws Error{invalid_argument} if `methods` is empty or lists a method twice.
CMC33_VERIFY_EXPORT void check_methods(const std::vector<Method>& methods);

/// One tally per method per thread: methods[m] named, or one "command" tally if `external`.
CMC33_VERIFY_EXPORT std::vector<std::vector<Tally>> make_tallies(int threads, const std::vector<Method>& methods,
                                                                 bool external);

/// Reports progress over passes that each count from 0: passes its callback the done count plus
/// the fields of the finished passes.
class Ticker {
public:
    Ticker(const ProgressCallback& callback, std::int64_t total,
           const std::atomic<std::int64_t>* mismatched)
        : callback_(callback), total_(total), mismatched_(mismatched),
          start_(std::chrono::steady_clock::now())
    {
    }
    void operator()(std::int64_t done_in_pass) const
    {
        if (!callback_) return;
        VerifyProgress p;
        p.done = done_before_ + done_in_pass;
        p.total = total_;
        p.mismatched = mismatched_ ? mismatched_->load() : 0;
        p.seconds = seconds();
        callback_(p);
    }
    void pass_done(std::int64_t count) { done_before_ += count; }
    std::int64_t done_before() const { return done_before_; }
    double seconds() const
    {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }

private:
    const ProgressCallback& callback_;
    std::int64_t total_;
    const std::atomic<std::int64_t>* mismatched_;
    std::chrono::steady_clock::time_point start_;
    std::int64_t done_before_ = 0;
};

/// Sums the per-thread tallies of each method, in thread order (totals do not depend on it).
CMC33_VERIFY_EXPORT std::vector<Tally> merge(std::vector<std::vector<Tally>>& per_thread, int max_failures);

/// The shell line that reruns an external command on a saved failing field: `in` the saved
/// volume, `out_base` the saved mesh's path without extension.
using RerunCommand =
    std::function<std::string(const std::filesystem::path& in, double iso, const std::filesystem::path& out_base)>;

/// Writes the failures of every method to `dir` (created if there is one) and moves the tallies'
/// reports into report.methods, with their failures_written counts. `rerun_external` gives the
/// line that reproduces a failure of the external tally, if there is one.
CMC33_VERIFY_EXPORT void finish(std::vector<Tally>& tallies, const std::filesystem::path& dir,
                                const RerunCommand& rerun_external, VerifyReport& report);

/// Runs body(thread, begin, end) over [0, total) in batches that `threads` workers pull from a
/// shared counter, and calls tick(done) on the calling thread about every 0.2 s while they run.
/// What a field yields must not depend on which thread ran it (it does not: every field has its
/// own generator and the tallies are sums). The first exception of a worker stops the others and
/// is rethrown here.
template <class Body, class Tick>
void run_parallel(std::int64_t total, int threads, std::int64_t batch, Tick&& tick, Body&& body)
{
    std::atomic<std::int64_t> next{0}, done{0};
    std::atomic<bool> stop{false};
    std::mutex mutex;
    std::condition_variable finished_cv;
    int finished = 0;
    std::vector<std::exception_ptr> errors(static_cast<std::size_t>(threads));
    auto worker = [&](int t) {
        try {
            while (!stop.load(std::memory_order_relaxed)) {
                const std::int64_t begin = next.fetch_add(batch);
                if (begin >= total) break;
                const std::int64_t end = std::min(total, begin + batch);
                body(t, begin, end);
                done.fetch_add(end - begin);
            }
        } catch (...) {
            errors[static_cast<std::size_t>(t)] = std::current_exception();
            stop = true;
        }
        const std::lock_guard<std::mutex> lock(mutex);
        ++finished;
        finished_cv.notify_one();
    };
    std::vector<std::thread> pool;
    pool.reserve(static_cast<std::size_t>(threads));
    try {
        for (int t = 0; t < threads; ++t) pool.emplace_back(worker, t);
    } catch (...) {
        stop = true;
        for (auto& th : pool) th.join();
        throw;
    }
    {
        std::unique_lock<std::mutex> lock(mutex);
        while (finished < static_cast<int>(pool.size())) {
            finished_cv.wait_for(lock, std::chrono::milliseconds(200));
            lock.unlock();
            tick(done.load());
            lock.lock();
        }
    }
    for (auto& th : pool) th.join();
    for (auto& e : errors) {
        if (e) std::rethrow_exception(e);
    }
}

/// Single-quoted for a POSIX shell.
CMC33_VERIFY_EXPORT std::string shell_quote(const std::string& text);

/// The value as the shortest decimal text that reads back as the same double.
CMC33_VERIFY_EXPORT std::string number_text(double value);

} // namespace cmc33::verification::detail
