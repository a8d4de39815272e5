// Independent pieces of work whose results travel as text, so that a caller can share them over
// processes (sweep/farm.hpp: MPI ranks, threads within each) as well as over threads. The field's
// planes (field.hpp) and the design's starts and verification runs (design.hpp) go through one.
#pragma once

#include <functional>
#include <string>

namespace plate {

// run(n, work, done): work(i) runs once for every i in [0, n), on any thread of any process, and
// done(i, work(i)) is called in the calling process for every i, one call at a time, in any order.
// Under MPI every rank calls the runner with the same n and every rank gets every done(i, ...), so
// all ranks take the same path afterwards. work must not throw (a failure is a result); a task's
// text must carry everything done reads, exactly (exact_text below), so the result is the same
// wherever the task ran.
using TaskRunner = std::function<void(int n, const std::function<std::string(int)>& work,
                                      const std::function<void(int, const std::string&)>& done)>;

// Threads of this process (0: all cores): work(i) on the threads, done in the caller's thread as the
// tasks finish.
TaskRunner thread_tasks(int threads);

// A double as text that reads back to the same bits (C99 hexadecimal; nan, inf, -inf), and back.
std::string exact_text(double x);
double exact_value(const std::string& text);   // throws std::invalid_argument on anything else

}   // namespace plate
