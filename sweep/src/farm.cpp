// The thread farm, and what the program needs to know about MPI whether or not it was built with it.
#include "plate/farm.hpp"

#include "plate/progress.hpp"

#include <atomic>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace plate::sweep {
namespace {

class ThreadFarm : public Farm {
public:
    explicit ThreadFarm(int threads)
        : threads_(threads > 0 ? threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()))) {}
    int workers() const override { return threads_; }
    std::string describe() const override {
        return "1 process x " + std::to_string(threads_) + (threads_ == 1 ? " thread" : " threads");
    }
    void broadcast(std::string&) override {}
    void run(const std::vector<int>& todo, const std::function<std::string(int)>& work,
             const std::function<void(int, const std::string&)>& done) override {
        std::atomic<std::size_t> next{0};
        std::mutex m;
        // The first exception: a done() that threw (a journal that cannot be written) or a work() asked
        // to stop (Interrupted: every thread polls the caller's stop request, progress.hpp).
        std::exception_ptr failure;
        const StopRequest* const stop = current_stop_request();
        auto worker = [&] {
            const StopScope scope(stop);
            for (std::size_t k; (k = next.fetch_add(1)) < todo.size();) {
                std::string r;
                try {
                    r = work(todo[k]);
                } catch (...) {
                    std::lock_guard<std::mutex> lock(m);
                    if (!failure) failure = std::current_exception();
                    next = todo.size();
                    return;
                }
                std::lock_guard<std::mutex> lock(m);
                if (failure) return;
                try {
                    done(todo[k], r);
                } catch (...) {
                    failure = std::current_exception();
                    next = todo.size();
                }
            }
        };
        const int n =
            static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(threads_), std::max<std::size_t>(todo.size(), 1)));
        std::vector<std::thread> pool;
        for (int t = 1; t < n; ++t) pool.emplace_back(worker);
        worker();
        for (auto& t : pool) t.join();
        if (failure) std::rethrow_exception(failure);
    }

private:
    int threads_;
};

int env_int(const char* name) {
    const char* v = std::getenv(name);
    return v ? std::atoi(v) : 0;
}

}   // namespace

std::unique_ptr<Farm> thread_farm(int threads) { return std::make_unique<ThreadFarm>(threads); }

TaskRunner farm_tasks(Farm& farm) {
    return [&farm](int n, const std::function<std::string(int)>& work, const std::function<void(int, const std::string&)>& done) {
        std::vector<int> todo;
        if (farm.root())
            for (int i = 0; i < n; ++i) todo.push_back(i);
        std::vector<std::string> results(farm.root() ? static_cast<std::size_t>(n) : 0);
        farm.run(todo, work, [&](int i, const std::string& r) {
            results[static_cast<std::size_t>(i)] = r;
            done(i, r);
        });
        if (farm.ranks() == 1) return;
        // Every result to every rank: "length:text" n times.
        std::string all;
        if (farm.root())
            for (const std::string& r : results) all += std::to_string(r.size()) + ':' + r;
        farm.broadcast(all);
        if (farm.root()) return;
        std::size_t at = 0;
        for (int i = 0; i < n; ++i) {
            const std::size_t colon = all.find(':', at);
            if (colon == std::string::npos) throw std::runtime_error("farm_tasks: the broadcast results are damaged");
            const std::size_t len = std::stoul(all.substr(at, colon - at));
            done(i, all.substr(colon + 1, len));
            at = colon + 1 + len;
        }
    };
}

bool mpi_launched() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"})
        if (env_int(v) > 1) return true;
    return false;
}

#ifndef PLATE_HAVE_MPI
bool mpi_built() { return false; }
std::unique_ptr<Farm> mpi_farm(int) {
    throw std::runtime_error("this plate was built without MPI (install libopenmpi-dev and rebuild)");
}
#endif

}   // namespace plate::sweep
