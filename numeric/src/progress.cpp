#include "plate/progress.hpp"

#include <limits>

namespace plate {

namespace {
thread_local const StopRequest* t_request = nullptr;
}

StopScope::StopScope(const StopRequest* request) : previous_(t_request) {
    if (request) t_request = request;
}

StopScope::~StopScope() { t_request = previous_; }

const StopRequest* current_stop_request() { return t_request; }

void throw_if_stopped() {
    if (t_request && t_request->requested()) throw Interrupted();
}

double seconds_left(long done, long total, double seconds) {
    if (done >= total) return 0;
    if (done <= 0) return std::numeric_limits<double>::quiet_NaN();
    return seconds / static_cast<double>(done) * static_cast<double>(total - done);
}

Progress ProgressClock::at(long done, long total) const {
    Progress p;
    p.done = done;
    p.total = total;
    p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    p.seconds_left = seconds_left(done, total, p.seconds);
    return p;
}

}   // namespace plate
