#include "plate/tasks.hpp"
#include "plate/progress.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

namespace plate {

TaskRunner thread_tasks(int threads) {
    return
        [threads](int n, const std::function<std::string(int)>& work, const std::function<void(int, const std::string&)>& done) {
            // Each worker polls the caller's stop request (progress.hpp); the first exception one throws
            // stops the others taking tasks and is rethrown once all have returned.
            std::atomic<int> next{0};
            std::atomic<bool> failed{false};
            std::exception_ptr error;
            std::mutex done_mutex;
            const StopRequest* request = current_stop_request();
            auto worker = [&] {
                const StopScope scope(request);
                try {
                    for (int i; !failed && (i = next.fetch_add(1)) < n;) {
                        const std::string r = work(i);
                        std::lock_guard<std::mutex> lock(done_mutex);
                        done(i, r);
                    }
                } catch (...) {
                    std::lock_guard<std::mutex> lock(done_mutex);
                    if (!error) error = std::current_exception();
                    failed = true;
                }
            };
            const int hw = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
            const int nt = std::max(1, std::min(n, threads > 0 ? threads : hw));
            std::vector<std::thread> pool;
            for (int t = 1; t < nt; ++t) pool.emplace_back(worker);
            worker();
            for (auto& t : pool) t.join();
            if (error) std::rethrow_exception(error);
        };
}

std::string exact_text(double x) {
    if (std::isnan(x)) return "nan";
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
    char buf[40];
    std::snprintf(buf, sizeof buf, "%a", x);
    return buf;
}

double exact_value(const std::string& text) {
    if (text == "nan") return std::nan("");
    if (text == "inf") return HUGE_VAL;
    if (text == "-inf") return -HUGE_VAL;
    char* end = nullptr;
    const double x = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size()) throw std::invalid_argument("not an exact number: '" + text + "'");
    return x;
}

}   // namespace plate
