// The MPI farm (built when Open MPI is found). Rank 0 hands out tasks one at a time (self-
// scheduling) to its own threads and to the other ranks' threads, and collects the results; only
// each rank's main thread calls MPI (MPI_THREAD_FUNNELED).
//
// Protocol (tags): a worker rank first sends HELLO with its thread count T; rank 0 answers with
// 2T ASSIGN messages (a task index, or -1: no more) -- two tasks in flight per thread, so that a
// thread finds its next task waiting whatever the round trip. Each finished task returns as RESULT
// ("index\n" + text), which rank 0 answers with the next ASSIGN. A worker rank ends after 2T stops;
// rank 0 once every slot of every rank has had its stop and its own threads (which take tasks from
// the list directly) are done. Per task the wire carries a 4-byte index out and the result text
// back (~1.3 kB for a fig4 fixed-point row).
//
// The main threads poll (MPI_Iprobe, then a 1 ms sleep when idle) rather than block in MPI_Recv:
// Open MPI's blocking receive spins, which would take a core from the threads computing beside it.
// Two tasks in flight per thread and a 1 ms poll: shorter polls cost compute, longer ones idle time
// (docs/decisions.md, "Self-scheduling with two tasks in flight per thread, polled at 1 ms").
#include "plate/farm.hpp"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace plate::sweep {
namespace {

constexpr int kHello = 11, kAssign = 12, kResult = 13;
constexpr int kDepth = 2;   // tasks in flight per remote thread

void nap() { std::this_thread::sleep_for(std::chrono::milliseconds(1)); }

// A thread-safe queue of tasks for the rank's threads, and of their results for the main thread.
struct Local {
    std::mutex m;
    std::condition_variable cv;
    std::deque<int> tasks;
    std::deque<std::pair<int, std::string>> results;
    bool closed = false;

    void push(int i) {
        {
            std::lock_guard<std::mutex> l(m);
            tasks.push_back(i);
        }
        cv.notify_one();
    }
    void close() {
        {
            std::lock_guard<std::mutex> l(m);
            closed = true;
        }
        cv.notify_all();
    }
    bool pop(int& i) {
        std::unique_lock<std::mutex> l(m);
        cv.wait(l, [&] { return closed || !tasks.empty(); });
        if (tasks.empty()) return false;
        i = tasks.front();
        tasks.pop_front();
        return true;
    }
    void finish(int i, std::string r) {
        std::lock_guard<std::mutex> l(m);
        results.emplace_back(i, std::move(r));
    }
    bool take(std::pair<int, std::string>& r) {
        std::lock_guard<std::mutex> l(m);
        if (results.empty()) return false;
        r = std::move(results.front());
        results.pop_front();
        return true;
    }
};

class MpiFarm : public Farm {
public:
    explicit MpiFarm(int threads) {
        int provided = 0;
        MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
        if (provided < MPI_THREAD_FUNNELED) {
            MPI_Finalize();
            throw std::runtime_error("the MPI library does not provide MPI_THREAD_FUNNELED");
        }
        MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
        MPI_Comm_size(MPI_COMM_WORLD, &ranks_);
        if (threads <= 0) {
            const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
            const int on_node = local ? std::max(1, std::atoi(local)) : 1;
            threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / on_node);
        }
        threads_ = threads;
        workers_ = threads;
    }
    ~MpiFarm() override { MPI_Finalize(); }
    MpiFarm(const MpiFarm&) = delete;
    MpiFarm& operator=(const MpiFarm&) = delete;

    int rank() const override { return rank_; }
    int ranks() const override { return ranks_; }
    int workers() const override { return workers_; }
    std::string describe() const override {
        return std::to_string(ranks_) + " MPI ranks x " + std::to_string(threads_) + (threads_ == 1 ? " thread" : " threads") +
               " (rank 0's)";
    }
    void broadcast(std::string& text) override {
        unsigned long n = text.size();
        MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG, 0, MPI_COMM_WORLD);
        text.resize(n);
        for (unsigned long at = 0; at < n; at += 1UL << 30)   // (counts are ints)
            MPI_Bcast(text.data() + at, static_cast<int>(std::min(n - at, 1UL << 30)), MPI_CHAR, 0, MPI_COMM_WORLD);
    }
    void abort(int code) override { MPI_Abort(MPI_COMM_WORLD, code); }
    void barrier() override { MPI_Barrier(MPI_COMM_WORLD); }

    void run(const std::vector<int>& todo, const std::function<std::string(int)>& work,
             const std::function<void(int, const std::string&)>& done) override {
        std::exception_ptr failure;   // a done() that threw (a journal that cannot be written): the
        try {                         // caller reports it and aborts every rank
            if (rank_ == 0)
                root(todo, work, done);
            else
                worker(work);
        } catch (...) {
            failure = std::current_exception();
        }
        if (failure) std::rethrow_exception(failure);
        MPI_Barrier(MPI_COMM_WORLD);
    }

private:
    // Rank 0: its own threads take tasks straight from the list; its main thread serves the other
    // ranks. done() is called under one mutex from both.
    void root(const std::vector<int>& todo, const std::function<std::string(int)>& work,
              const std::function<void(int, const std::string&)>& done) {
        std::mutex m;   // the list's cursor, done(), the failure
        std::size_t next = 0;
        std::exception_ptr failure;
        auto take = [&] { return !failure && next < todo.size() ? todo[next++] : -1; };
        auto report = [&](int i, const std::string& r) {   // (m held)
            if (failure) return;
            try {
                done(i, r);
            } catch (...) {
                failure = std::current_exception();
            }
        };
        std::vector<std::thread> pool;
        for (int t = 0; t < threads_; ++t)
            pool.emplace_back([&] {
                for (;;) {
                    int i;
                    {
                        std::lock_guard<std::mutex> l(m);
                        i = take();
                    }
                    if (i < 0) return;
                    const std::string r = work(i);
                    std::lock_guard<std::mutex> l(m);
                    report(i, r);
                }
            });
        // The other ranks: kDepth tasks per thread in flight (so that a thread finds its next task
        // waiting, whatever the round trip), one more for each result; -1 when the list is done.
        int slots = 0, stops = 0, hellos = 0;   // remote task slots; stops sent; ranks heard from
        workers_ = threads_;
        std::string buf;
        while (hellos < ranks_ - 1 || stops < slots) {
            int flag = 0;
            MPI_Status st;
            MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st);
            if (!flag) {
                nap();
                continue;
            }
            int n = 0;
            MPI_Get_count(&st, MPI_CHAR, &n);
            buf.resize(static_cast<std::size_t>(n));
            MPI_Recv(buf.data(), n, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            int answers = 1;
            std::vector<int> next_tasks;
            {
                std::lock_guard<std::mutex> l(m);
                if (st.MPI_TAG == kHello) {
                    const int t = std::max(1, std::atoi(buf.c_str()));
                    answers = kDepth * t;
                    slots += answers;
                    workers_ += t;
                    ++hellos;
                } else {   // kResult
                    const std::size_t nl = buf.find('\n');
                    report(std::atoi(buf.c_str()), buf.substr(nl + 1));
                }
                for (int k = 0; k < answers; ++k) next_tasks.push_back(take());
            }
            for (int i : next_tasks) {
                if (i < 0) ++stops;
                MPI_Send(&i, 1, MPI_INT, st.MPI_SOURCE, kAssign, MPI_COMM_WORLD);
            }
        }
        for (auto& t : pool) t.join();
        if (failure) std::rethrow_exception(failure);
    }

    // Another rank: its threads take the tasks rank 0 sends; its main thread passes them on and
    // sends the results back.
    void worker(const std::function<std::string(int)>& work) {
        Local local;
        std::vector<std::thread> pool;
        for (int t = 0; t < threads_; ++t)
            pool.emplace_back([&] {
                for (int i; local.pop(i);) local.finish(i, work(i));
            });
        const std::string hello = std::to_string(threads_);
        MPI_Send(hello.data(), static_cast<int>(hello.size()), MPI_CHAR, 0, kHello, MPI_COMM_WORLD);
        int stops = 0, busy = 0;
        while (stops < kDepth * threads_ || busy > 0) {
            bool idle = true;
            int flag = 0;
            MPI_Iprobe(0, kAssign, MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE);
            if (flag) {
                idle = false;
                int i = -1;
                MPI_Recv(&i, 1, MPI_INT, 0, kAssign, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                if (i < 0)
                    ++stops;
                else {
                    local.push(i);
                    ++busy;
                }
            }
            std::pair<int, std::string> r;
            while (local.take(r)) {
                idle = false;
                --busy;
                const std::string msg = std::to_string(r.first) + "\n" + r.second;
                MPI_Send(msg.data(), static_cast<int>(msg.size()), MPI_CHAR, 0, kResult, MPI_COMM_WORLD);
            }
            if (idle) nap();
        }
        local.close();
        for (auto& t : pool) t.join();
    }

    int rank_ = 0, ranks_ = 1, threads_ = 1, workers_ = 1;
};

}   // namespace

bool mpi_built() { return true; }
std::unique_ptr<Farm> mpi_farm(int threads) { return std::make_unique<MpiFarm>(threads); }

}   // namespace plate::sweep
