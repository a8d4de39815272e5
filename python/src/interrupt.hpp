// Long calls from Python: interruptible by Ctrl-C and reporting progress (issue 54).
//
// The computation runs on a thread of its own with the GIL released, under a StopRequest
// (plate/progress.hpp) its every integrator step polls. The interpreter's thread -- the only one on
// which Python runs signal handlers -- waits for it, and every kPollPeriod takes the GIL, calls
// PyErr_CheckSignals() and the `progress` callable (with the latest plate.Progress, if it changed).
// A signal handler's exception (KeyboardInterrupt) or the callable's sets the request; the
// computation unwinds (Interrupted, no result) and the exception is raised in Python.
// (docs/decisions/design-and-tools.md, Interrupting long calls: where the request is polled)
#pragma once

#include "plate/progress.hpp"

#include <pybind11/pybind11.h>

#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

namespace plate::python {

namespace py = pybind11;

// How often the interpreter's thread looks at signals and progress while a long call runs.
constexpr std::chrono::milliseconds kPollPeriod{50};

// What a long call's threads report: the latest progress, timed from the call's start.
class Watch {
public:
    void report(long done, long total) {
        const std::lock_guard<std::mutex> lock(m_);
        latest_ = clock_.at(done, total);
        fresh_ = true;
    }
    // The latest progress if it changed since the last take.
    bool take(Progress& p) {
        const std::lock_guard<std::mutex> lock(m_);
        if (!fresh_) return false;
        p = latest_;
        fresh_ = false;
        return true;
    }
    StopRequest stop;

private:
    std::mutex m_;
    ProgressClock clock_;
    Progress latest_;
    bool fresh_ = false;
};

// With the GIL held: signals' handlers, then progress(latest) if it changed and progress is not None.
// False when either raised (the Python error is set).
bool poll_python(const py::object& progress, Watch& watch);

// work(watch) -> R off the interpreter's thread, interruptible (above). Raises what a signal handler
// or progress raised; else returns work's result or rethrows its exception.
template <class Work>
auto interruptible(const py::object& progress, Work&& work) -> decltype(work(std::declval<Watch&>())) {
    using R = decltype(work(std::declval<Watch&>()));
    Watch watch;
    std::optional<R> result;
    std::exception_ptr error;
    std::mutex m;
    std::condition_variable cv;
    bool finished = false, raised = false;
    {
        const py::gil_scoped_release free;
        std::thread worker([&] {
            const StopScope scope(&watch.stop);
            try {
                result.emplace(work(watch));
            } catch (...) {
                error = std::current_exception();
            }
            const std::lock_guard<std::mutex> lock(m);
            finished = true;
            cv.notify_all();
        });
        std::unique_lock<std::mutex> lock(m);
        while (!cv.wait_for(lock, kPollPeriod, [&] { return finished; })) {
            if (raised) continue;   // (asked to stop: waiting for the unwinding)
            lock.unlock();
            {
                const py::gil_scoped_acquire held;
                raised = !poll_python(progress, watch);
            }
            if (raised) watch.stop.request();
            lock.lock();
        }
        lock.unlock();
        worker.join();
    }
    if (!raised && !error) raised = !poll_python(progress, watch);   // (the last progress: done = total)
    if (raised) throw py::error_already_set();
    if (error) std::rethrow_exception(error);
    return std::move(*result);
}

}   // namespace plate::python
