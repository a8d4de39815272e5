// Long computations: how far they are (done of total, seconds spent, an estimate of the seconds
// left) and a request to stop them. The one home of both: fields, fixed points, designs,
// simulations, robustness and identification report and stop through what is declared here.
//
// Stopping: a StopRequest is set from any thread (or a signal handler: a lock-free atomic). A long
// call polls the request of its thread (StopScope installs one; the call's worker threads inherit
// the request of the thread that started them) at every step of the integrator, so a request is
// seen within one step wherever the work is; the call then throws Interrupted and returns no
// partial result. (docs/decisions/design-and-tools.md, Interrupting long calls: where the request is polled)
#pragma once

#include <atomic>
#include <chrono>
#include <stdexcept>

namespace plate {

// A long computation was asked to stop (StopRequest) and unwound: no result, partial or whole.
struct Interrupted : std::runtime_error {
    Interrupted() : std::runtime_error("interrupted: the computation was asked to stop") {}
};

// A request to stop: set once, from any thread; never cleared (a new computation takes a new one).
class StopRequest {
public:
    void request() noexcept { flag_.store(true, std::memory_order_relaxed); }
    bool requested() const noexcept { return flag_.load(std::memory_order_relaxed); }

private:
    std::atomic<bool> flag_{false};
};

// Installs `request` (nullptr: keeps the one installed) as the request this thread's computations
// poll, for the scope's life.
class StopScope {
public:
    explicit StopScope(const StopRequest* request);
    ~StopScope();
    StopScope(const StopScope&) = delete;
    StopScope& operator=(const StopScope&) = delete;

private:
    const StopRequest* previous_;
};

// The request this thread's computations poll (nullptr: none); a long call that starts threads
// hands it to them (a StopScope in each).
const StopRequest* current_stop_request();

// Throws Interrupted when this thread's stop request is set. Cheap (a thread-local pointer and a
// relaxed atomic load): the integrator calls it at every step.
void throw_if_stopped();

// How far a long computation is. seconds_left extrapolates the mean time per unit so far to the
// units left (NaN before the first unit is done; 0 when all are).
struct Progress {
    long done = 0, total = 0;
    double seconds = 0;        // since the computation started
    double seconds_left = 0;   // the estimate
};

// The estimate: seconds spent per unit done, times the units left (NaN if none done; 0 if all are).
double seconds_left(long done, long total, double seconds);

// A computation's clock: Progress from the units done, timed from the clock's construction.
class ProgressClock {
public:
    Progress at(long done, long total) const;

private:
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}   // namespace plate
