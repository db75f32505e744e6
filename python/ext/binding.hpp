#pragma once
/// @file binding.hpp
/// What the parts of the extension module share: numpy arrays read in place as GridViews, and
/// running library work without the GIL so that Ctrl-C and a progress callback still reach it.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <type_traits>
#include <utility>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/volume.hpp"

namespace cmc33::python {

namespace py = pybind11;

/// cmc33.Mesh (bound in module.cpp): a cmc33::Mesh whose arrays numpy reads in place.
struct PyMesh {
    Mesh mesh;
    std::optional<ExtractStats> stats; ///< cells per subcase, for meshes extract() made
    bool normals = false;              ///< the mesh has normals (an empty mesh too, if asked for)
};

/// A 3D numpy array as the library reads it, in place: sample (i, j, k) is array[k, j, i], so x is
/// the array's last axis (C order is the library's dense layout). Strides are in samples, any
/// sign. `array` keeps the samples alive.
struct Samples {
    py::array array;
    ScalarType type = ScalarType::u8;
    const void* data = nullptr;
    Index3 dims{0, 0, 0};
    Index3 strides{0, 0, 0};
    std::int64_t count() const noexcept { return dims[0] * dims[1] * dims[2]; }
};

/// @throws Error{invalid_argument} unless `array` is 3D with samples of one of the eight types
///         (bool read as uint8), in the machine's byte order, aligned, every stride a whole number
///         of samples. The Python layer (cmc33/_arrays.py) converts other arrays first.
Samples samples_of(const py::array& array, const char* what = "volume");

/// The frame of volume.hpp: spacing, origin and direction of the library's axes x, y, z.
struct Frame {
    Vec3 spacing{1, 1, 1};
    Vec3 origin{0, 0, 0};
    Mat3 direction = kIdentity3;
};

/// Calls f(GridView<T>) over the samples with T their type.
template <class F> decltype(auto) visit(const Samples& s, const Frame& frame, F&& f)
{
    return dispatch_scalar_type(s.type, [&](auto tag) -> decltype(auto) {
        using T = decltype(tag);
        const GridView<T> grid{static_cast<const T*>(s.data), s.dims, s.strides, frame.spacing, frame.origin,
                               frame.direction};
        return f(grid);
    });
}

/// Between work running without the GIL and the thread that waits for it.
class Control {
public:
    /// Called by the work: records how far it is; false once it is to stop.
    bool keep_going(double fraction) noexcept
    {
        fraction_.store(fraction, std::memory_order_relaxed);
        return !stop_.load(std::memory_order_relaxed);
    }
    bool stopped() const noexcept { return stop_.load(std::memory_order_relaxed); }
    void stop() noexcept { stop_.store(true, std::memory_order_relaxed); }
    double fraction() const noexcept { return fraction_.load(std::memory_order_relaxed); }

private:
    std::atomic<bool> stop_{false};
    std::atomic<double> fraction_{0};
};

/// Work this small runs on the calling thread (without the GIL) when nobody asked for progress:
/// it ends before a Ctrl-C could matter, and a thread of its own would cost more than the work.
inline constexpr std::int64_t kBackgroundSamples = std::int64_t{1} << 18;

/// Runs work(control) without the GIL and returns its result. With `background` the work runs on
/// a thread of its own while the calling thread waits, waking every 20 ms to take the GIL, run
/// Python's pending signal handlers (a Ctrl-C raises KeyboardInterrupt there: PyErr_CheckSignals
/// only acts on the main thread, which is why the work is not the one to call it) and call
/// progress(fraction) if that is not None. An exception from either, or progress returning a false
/// value other than None,
/// stops the work (control.keep_going() returns false from then on); once the work has ended,
/// that exception is raised, or Error{cancelled} for the False. progress(1.0) is the last call of
/// a run that completes (its answer no longer matters).
template <class R> R run_interruptible(bool background, const py::object& progress, const std::function<R(Control&)>& work)
{
    Control control;
    if (!background) {
        py::gil_scoped_release nogil;
        return work(control);
    }
    std::optional<R> result;
    std::exception_ptr work_error;
    std::mutex mutex;
    std::condition_variable ended;
    bool done = false;
    std::thread worker([&] {
        try {
            result.emplace(work(control));
        } catch (...) {
            work_error = std::current_exception();
        }
        {
            const std::lock_guard lock(mutex);
            done = true;
        }
        ended.notify_one();
    });

    std::exception_ptr caller_error;
    bool declined = false; // progress returned False
    double reported = -1;
    for (;;) {
        {
            py::gil_scoped_release nogil;
            std::unique_lock lock(mutex);
            if (ended.wait_for(lock, std::chrono::milliseconds(20), [&] { return done; })) break;
        }
        if (control.stopped()) continue; // stopping: wait for the work to notice
        try {
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
            const double fraction = control.fraction();
            if (!progress.is_none() && fraction != reported) {
                reported = fraction;
                const py::object answer = progress(fraction);
                if (!answer.is_none() && PyObject_Not(answer.ptr()) == 1) { // False (or 0, numpy's False)
                    declined = true;
                    control.stop();
                }
            }
        } catch (...) {
            caller_error = std::current_exception();
            control.stop();
        }
    }
    worker.join();
    if (caller_error) std::rethrow_exception(caller_error);
    if (work_error) std::rethrow_exception(work_error);
    if (declined) throw Error(Status::cancelled, "cancelled: the progress callback returned False");
    if (!progress.is_none()) progress(1.0);
    return std::move(*result);
}

/// `values` (a std::vector, moved here) as a numpy array that owns it, without a copy: a capsule
/// deletes the vector with the array. `columns` > 0 gives a 2D array of that many columns (the
/// size a multiple of it), 0 a 1D array.
template <class V> py::array_t<typename V::value_type> to_numpy(V&& values, std::int64_t columns = 0)
{
    static_assert(!std::is_reference_v<V>, "to_numpy takes the vector by std::move");
    using E = typename V::value_type;
    auto owned = std::make_unique<V>(std::move(values));
    V& v = *owned;
    const py::capsule free_when_done(owned.get(), [](void* o) { delete static_cast<V*>(o); });
    owned.release();
    const auto size = static_cast<py::ssize_t>(v.size());
    if (columns > 0) {
        const auto c = static_cast<py::ssize_t>(columns);
        return py::array_t<E>({size / c, c}, v.data(), free_when_done);
    }
    return py::array_t<E>({size}, v.data(), free_when_done);
}

/// Smallest and largest sample, NaN skipped (NaN, NaN if every sample is NaN); without the GIL,
/// interruptible as run_interruptible is. @throws Error{invalid_argument} for an empty array
std::pair<double, double> value_range(const Samples& samples, int threads);

} // namespace cmc33::python
